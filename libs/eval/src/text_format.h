// Number formatting of the evaluation's text reports (internal).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace bims::eval::detail
{
/** "%.4f" or "nan". */
inline std::string fmt4(double v)
{
	if (!std::isfinite(v)) return "nan";
	char b[64];
	std::snprintf(b, sizeof(b), "%.4f", v);
	return b;
}
}  // namespace bims::eval::detail
