#include <bims/eval/json.h>

#include <cmath>
#include <cstdio>

namespace bims::eval
{
std::string jsonNumber(double v)
{
	if (!std::isfinite(v)) return "null";
	char b[64];
	std::snprintf(b, sizeof(b), "%.9g", v);
	return b;
}

std::string jsonString(const std::string& s)
{
	std::string o = "\"";
	for (const char c : s)
	{
		switch (c)
		{
			case '"':
				o += "\\\"";
				break;
			case '\\':
				o += "\\\\";
				break;
			case '\n':
				o += "\\n";
				break;
			case '\t':
				o += "\\t";
				break;
			default:
				if (static_cast<unsigned char>(c) < 0x20)
				{
					char b[8];
					std::snprintf(b, sizeof(b), "\\u%04x", c);
					o += b;
				}
				else
					o += c;
		}
	}
	return o + "\"";
}
}  // namespace bims::eval
