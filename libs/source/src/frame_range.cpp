#include <bims/source/frame_source.h>

#include <stdexcept>

namespace bims::source
{
FrameRange FrameRange::parse(const std::string& s)
{
	const auto colon = s.find(':');
	if (colon == std::string::npos)
		throw std::invalid_argument(
		    "--frames '" + s + "': expected A:B (3D-scan indices, inclusive)");
	auto num = [&](const std::string& t, size_t def) -> size_t
	{
		if (t.empty()) return def;
		size_t pos = 0;
		long long v = -1;
		try
		{
			v = std::stoll(t, &pos);
		}
		catch (...)
		{
			pos = 0;
		}
		if (pos != t.size() || v < 0)
			throw std::invalid_argument("--frames '" + s + "': '" + t +
			                            "' is not a non-negative integer");
		return static_cast<size_t>(v);
	};
	FrameRange r;
	r.first = num(s.substr(0, colon), 0);
	r.last = num(s.substr(colon + 1), static_cast<size_t>(-1));
	if (r.first > r.last)
		throw std::invalid_argument("--frames '" + s + "': A > B");
	return r;
}

}  // namespace bims::source
