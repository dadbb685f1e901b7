// The clock of the pipeline's stage timings (frames.csv's ms_* columns,
// metrics.json): one home for libs/pipeline's sources. Private.
#pragma once

#include <chrono>

namespace bims::pipeline::detail
{
using Clock = std::chrono::steady_clock;

/** Milliseconds from \a t0 to now. */
inline double msSince(Clock::time_point t0)
{
	return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}
}  // namespace bims::pipeline::detail
