// Private helpers of the maps library.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace bims::maps
{
/** Cells ahead of the current one whose storage is prefetched when a grid
 * walks a frame's cells (their blocks are mostly out of cache). */
constexpr std::size_t kPrefetchAhead = 16;

/** Generic MRPT keys accepted in a map's creationOpts section. */
const std::vector<std::string>& mrptGenericMapKeys();
}  // namespace bims::maps
