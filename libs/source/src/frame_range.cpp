#include <bims/io/rawlog.h>
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

void checkFrameRangeInInputs(const FrameRange& range,
                             const std::vector<std::string>& rawlogs,
                             const std::string& rgbdLabel)
{
	if (range.first == 0 && !range.bounded()) return;
	const size_t need = (range.bounded() ? range.last : range.first) + 1;
	size_t n = 0;
	try
	{
		n = count3DScans(rawlogs, rgbdLabel, need);
	}
	catch (const std::exception&)
	{
		// a missing or truncated input: the run meets it as it does without
		// a range (the frames read whole processed, the error reported)
		return;
	}
	if (n >= need) return;
	std::string files;
	for (const auto& f : rawlogs) files += (files.empty() ? "" : ", ") + f;
	std::string msg =
	    "--frames " + range.toString() + ": the input (" + files + ") has " +
	    (n == 0 ? std::string("no 3D scan")
	            : std::to_string(n) + " 3D scans (0 to " +
	                  std::to_string(n - 1) + ")") +
	    (rgbdLabel.empty() ? std::string() : " with label '" + rgbdLabel + "'");
	if (range.first < n)
		msg +=
		    "; --frames " + std::to_string(range.first) + ": runs to its end";
	throw std::invalid_argument(msg);
}

}  // namespace bims::source
