#include <bims/common/stats.h>

#include <algorithm>
#include <cmath>

namespace bims
{
Percentiles Percentiles::of(std::vector<double> v)
{
	Percentiles p;
	p.n = v.size();
	if (v.empty()) return p;
	std::sort(v.begin(), v.end());
	p.median = v[v.size() / 2];
	p.p95 = v[std::min(v.size() - 1,
	                   static_cast<size_t>(std::ceil(0.95 * v.size())) - 1)];
	double s = 0;
	for (double x : v) s += x;
	p.mean = s / v.size();
	return p;
}

}  // namespace bims
