// One clock for every grabbed observation: the host's mrpt::Clock
// (UNIX time). Device stamps are mapped to it with an offset that follows the
// smallest observed (host arrival - device stamp), i.e. the least delayed
// sample, so that USB latency jitter does not move the stamps.
#pragma once

#include <mrpt/core/Clock.h>

namespace bims::grab
{
/** Now on the host clock [s]. */
inline double hostNow()
{
	return mrpt::Clock::toDouble(mrpt::Clock::now());
}

/** Maps a device clock [s] to the host clock [s]. */
class ClockMapper
{
 public:
	/** A device stamp and the host time it arrived; returns the host stamp.
	 * A device clock that goes backwards or jumps by more than \a resetS
	 * restarts the mapping. */
	double map(double deviceT, double hostArrivalT, double resetS = 1.0)
	{
		const double off = hostArrivalT - deviceT;
		if (!init_ || deviceT < lastDev_ || deviceT - lastDev_ > resetS ||
		    off < offset_)
			offset_ = off;
		init_ = true;
		lastDev_ = deviceT;
		return deviceT + offset_;
	}
	bool initialised() const { return init_; }

 private:
	bool init_ = false;
	double offset_ = 0, lastDev_ = 0;
};

}  // namespace bims::grab
