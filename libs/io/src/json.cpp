#include <bims/io/json.h>
#include <bims/io/output_paths.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

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

}  // namespace bims
