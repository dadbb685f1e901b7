#include <bims/eval/association.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

namespace bims::eval
{
IndexPairs associateGreedy(const std::vector<double>& a,
                           const std::vector<double>& b, double maxDifference,
                           double offset)
{
	// Candidates: for each a_i, the b_j within the window (b sorted).
	std::vector<std::tuple<double, size_t, size_t>> cand;
	size_t lo = 0;
	for (size_t i = 0; i < a.size(); i++)
	{
		while (lo < b.size() && b[lo] + offset <= a[i] - maxDifference) lo++;
		for (size_t j = lo; j < b.size(); j++)
		{
			const double d = std::abs(a[i] - (b[j] + offset));
			if (b[j] + offset >= a[i] + maxDifference) break;
			if (d < maxDifference) cand.emplace_back(d, i, j);
		}
	}
	std::sort(cand.begin(), cand.end());
	std::vector<bool> usedA(a.size(), false), usedB(b.size(), false);
	IndexPairs out;
	for (const auto& [d, i, j] : cand)
	{
		if (usedA[i] || usedB[j]) continue;
		usedA[i] = usedB[j] = true;
		out.emplace_back(i, j);
	}
	std::sort(out.begin(), out.end());
	return out;
}

size_t closestIndex(const std::vector<double>& v, double t)
{
	if (v.empty()) throw std::invalid_argument("closestIndex: empty list");
	const auto it = std::lower_bound(v.begin(), v.end(), t);
	if (it == v.begin()) return 0;
	if (it == v.end()) return v.size() - 1;
	const size_t j = static_cast<size_t>(it - v.begin());
	return (t - v[j - 1] <= v[j] - t) ? j - 1 : j;
}

}  // namespace bims::eval
