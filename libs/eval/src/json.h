// Minimal JSON writing helpers (internal).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace bims::eval::detail
{
/** A number, or null if not finite. */
inline std::string jnum(double v)
{
	if (!std::isfinite(v)) return "null";
	char b[64];
	std::snprintf(b, sizeof(b), "%.9g", v);
	return b;
}
/** A quoted, escaped string. */
std::string jstr(const std::string& s);
/** "%.4f" or "nan". */
inline std::string fmt4(double v)
{
	if (!std::isfinite(v)) return "nan";
	char b[64];
	std::snprintf(b, sizeof(b), "%.4f", v);
	return b;
}
}  // namespace bims::eval::detail
