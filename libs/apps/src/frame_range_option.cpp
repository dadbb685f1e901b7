#include <bims/apps/app.h>
#include <bims/apps/frame_range_option.h>

#include <stdexcept>

namespace bims::apps
{
source::FrameRange frameRangeOption(const std::string& text,
                                    const std::vector<std::string>& rawlogs,
                                    const std::string& rgbdLabel)
{
	if (text.empty()) return {};
	try
	{
		const auto range = source::FrameRange::parse(text);
		source::checkFrameRangeInInputs(range, rawlogs, rgbdLabel);
		return range;
	}
	catch (const std::invalid_argument& e)
	{
		throw UsageError(e.what());
	}
}

}  // namespace bims::apps
