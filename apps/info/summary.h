// Summary of a rawlog: observations per sensor label and class, rates, time
// span, image sizes.
#pragma once

#include <cstddef>
#include <map>
#include <ostream>
#include <string>

namespace bims::info
{
struct SensorSummary
{
	std::string label, className;
	size_t count = 0;
	double tFirst = 0, tLast = 0;              ///< UNIX time [s]
	std::map<std::string, size_t> imageSizes;  ///< "WxH" -> count
	double rateHz() const
	{
		return count > 1 && tLast > tFirst ? (count - 1) / (tLast - tFirst) : 0;
	}
};

struct RawlogSummary
{
	std::string path;
	size_t observations = 0;
	double tFirst = 0, tLast = 0;
	std::map<std::pair<std::string, std::string>, SensorSummary>
	    sensors;  ///< (label, class)
};

/** Reads the whole rawlog (either format); throws bims::RawlogError naming the
 * file for missing, truncated or corrupt files. */
RawlogSummary summarizeRawlog(const std::string& path);
void printSummary(const RawlogSummary& s, std::ostream& os);

}  // namespace bims::info
