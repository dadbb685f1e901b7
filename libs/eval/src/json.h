// Minimal JSON writing helpers (internal).
#pragma once

#include <bims/eval/json.h>
#include <cmath>
#include <cstdio>

#include <string>

namespace bims::eval::detail
{
inline std::string jnum(double v)
{
	return jsonNumber(v);
}
inline std::string jstr(const std::string& s)
{
	return jsonString(s);
}
/** "%.4f" or "nan". */
inline std::string fmt4(double v)
{
	if (!std::isfinite(v)) return "nan";
	char b[64];
	std::snprintf(b, sizeof(b), "%.4f", v);
	return b;
}
}  // namespace bims::eval::detail
