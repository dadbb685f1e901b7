// Reading what a program printed, for tests.
#pragma once

#include <fstream>
#include <sstream>
#include <stdexcept>
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

/** The whole content of the file at \a path. A file that cannot be opened
 * throws (the test fails naming it): a comparison of two files that were
 * never written must not pass as two empty texts. A test that expects a file
 * to be absent says so with std::filesystem::exists. */
inline std::string fileText(const std::string& path)
{
	std::ifstream f(path, std::ios::binary);
	if (!f) throw std::runtime_error("test: cannot read file '" + path + "'");
	std::stringstream s;
	s << f.rdbuf();
	return s.str();
}
}  // namespace bims::test
