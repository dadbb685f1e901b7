// Small helpers for writing JSON reports.
#pragma once

#include <string>

namespace bims::eval
{
/** A quoted JSON string with ", \ and control characters escaped. */
std::string jsonString(const std::string& s);
/** A JSON number (%.9g), or null if not finite. */
std::string jsonNumber(double v);
}  // namespace bims::eval
