// Stage timings (frames.csv's ms_* columns, metrics.json, the per-stage
// figures of the tools): one home for "milliseconds since t0".
#pragma once

#include <chrono>

namespace bims
{
/** Milliseconds of the steady clock from \a t0 to now. */
inline double msSince(std::chrono::steady_clock::time_point t0)
{
	return std::chrono::duration<double, std::milli>(
	           std::chrono::steady_clock::now() - t0)
	    .count();
}
}  // namespace bims
