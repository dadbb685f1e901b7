#include <bims/common/errors.h>

#include <cstdlib>
#include <sstream>

namespace bims
{
std::string withoutBacktrace(const std::string& what)
{
	if (std::getenv("BIMS_BACKTRACE")) return what;
	std::string out, line;
	std::istringstream in(what);
	while (std::getline(in, line))
	{
		if (line.rfind("Call stack backtrace:", 0) == 0) break;
		if (line.find("==== MRPT exception ====") != std::string::npos)
			continue;
		if (line.empty()) continue;
		out += (out.empty() ? "" : "; ") + line;
	}
	return out.empty() ? what : out;
}

}  // namespace bims
