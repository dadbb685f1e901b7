// Reading what a program printed, for tests.
#pragma once

#include <string>

namespace bims::test
{
/** The rest of the line after the first \a head in \a text ("" if absent):
 * e.g. the file named after "parameters from ". */
inline std::string restOfLineAfter(const std::string& text,
                                   const std::string& head)
{
	const auto at = text.find(head);
	if (at == std::string::npos) return {};
	const auto from = at + head.size();
	return text.substr(from, text.find('\n', from) - from);
}
}  // namespace bims::test
