// The one summary of a series of measurements (stage timings of every
// program): median, 95th percentile, mean.
#pragma once

#include <cstddef>
#include <vector>

namespace bims
{
/** Median (the element of rank n/2 once sorted), 95th percentile (rank
 * ceil(0.95 n) - 1) and mean of a series; zeros for an empty one. */
struct Percentiles
{
	double median = 0, p95 = 0, mean = 0;
	size_t n = 0;
	static Percentiles of(std::vector<double> v);
};

}  // namespace bims
