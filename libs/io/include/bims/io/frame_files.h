// Per-frame files: NNNNNN.EXT, NNNNNN = the index of the 3D scan in the
// input (from 0). bims-run's masks, the simulator's ground-truth masks and
// every reader of them (bims-odom --masks, bims-eval masks, the viewer).
#pragma once

#include <cstdio>
#include <string>

namespace bims
{
/** "000042.png" for index 42 and ext "png". */
inline std::string frameFileName(long index, const char* ext = "png")
{
	char buf[48];
	std::snprintf(buf, sizeof(buf), "%06ld.%s", index, ext);
	return buf;
}
}  // namespace bims
