#include "summary.h"

#include <bims/io/rawlog.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/system/datetime.h>

#include <cstdio>

namespace bims::info
{
RawlogSummary summarizeRawlog(const std::string& path)
{
	RawlogSummary s;
	s.path = path;
	RawlogReader r(path);
	bool first = true;
	while (auto o = r.next())
	{
		const double t = mrpt::Clock::toDouble(o->timestamp);
		auto& ss = s.sensors[{o->sensorLabel, o->GetRuntimeClass()->className}];
		if (ss.count == 0)
		{
			ss.label = o->sensorLabel;
			ss.className = o->GetRuntimeClass()->className;
			ss.tFirst = t;
		}
		ss.tLast = t;
		ss.count++;
		if (auto o3 =
		        std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
		            o))
		{
			char b[64];
			std::snprintf(
			    b, sizeof(b), "depth %dx%d%s", int(o3->rangeImage.cols()),
			    int(o3->rangeImage.rows()),
			    o3->hasIntensityImage
			        ? (" rgb " + std::to_string(o3->intensityImage.getWidth()) +
			           "x" + std::to_string(o3->intensityImage.getHeight()))
			              .c_str()
			        : "");
			ss.imageSizes[b]++;
		}
		else if (auto oi =
		             std::dynamic_pointer_cast<mrpt::obs::CObservationImage>(o))
		{
			ss.imageSizes[std::to_string(oi->image.getWidth()) + "x" +
			              std::to_string(oi->image.getHeight())]++;
		}
		if (first || t < s.tFirst) s.tFirst = t;
		if (first || t > s.tLast) s.tLast = t;
		first = false;
		s.observations++;
	}
	return s;
}

void printSummary(const RawlogSummary& s, std::ostream& os)
{
	char b[512];
	os << "rawlog:        " << s.path << "\n";
	std::snprintf(b, sizeof(b), "observations:  %zu\n", s.observations);
	os << b;
	if (s.observations > 0)
	{
		std::snprintf(
		    b, sizeof(b),
		    "time span:     %s .. %s UTC\nduration:      %.3f s\n",
		    mrpt::system::dateTimeToString(mrpt::Clock::fromDouble(s.tFirst))
		        .c_str(),
		    mrpt::system::dateTimeToString(mrpt::Clock::fromDouble(s.tLast))
		        .c_str(),
		    s.tLast - s.tFirst);
		os << b;
	}
	os << "sensors:\n";
	for (const auto& [key, ss] : s.sensors)
	{
		std::snprintf(b, sizeof(b), "  %-14s %-28s %7zu obs  %9.3f Hz  %.3f s",
		              ss.label.c_str(), ss.className.c_str(), ss.count,
		              ss.rateHz(), ss.tLast - ss.tFirst);
		os << b;
		for (const auto& [sz, n] : ss.imageSizes)
			os << "  [" << sz << " x" << n << "]";
		os << "\n";
	}
}

}  // namespace bims::info
