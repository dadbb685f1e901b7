#include <bims/io/json.h>
#include <bims/io/output_paths.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace bims
{
Json jsonNumber(double v, int decimals)
{
	if (!std::isfinite(v)) return nullptr;
	char b[64];
	if (decimals < 0)
		std::snprintf(b, sizeof(b), "%.9g", v);
	else
		std::snprintf(b, sizeof(b), "%.*f", decimals, v);
	return std::strtod(b, nullptr);
}

std::string jsonText(const Json& j)
{
	return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

std::string jsonLine(const Json& j)
{
	return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

void writeJsonFile(const std::string& path, const Json& j)
{
	writeFileAtomically(path, jsonText(j));
}

Json readJsonFile(const std::string& path)
{
	std::ifstream f(path);
	if (!f) throw std::runtime_error(path + ": cannot open");
	try
	{
		return Json::parse(f);
	}
	catch (const std::exception& e)
	{
		throw std::runtime_error(path + ": not JSON: " + e.what());
	}
}

}  // namespace bims
