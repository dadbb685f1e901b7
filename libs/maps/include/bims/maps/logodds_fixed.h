// Fixed-point log-odds of the tier-0 grid. Integer arithmetic makes decay
// exact and associative, so the lazy decay (k missed frames applied at once)
// equals k eager per-frame decays bit for bit.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace bims::maps
{
/** Log-odds in units of 2^-20 (quantum 9.5e-7, range +-2048). */
using LogOddsFx = int32_t;
constexpr double kLogOddsScale = 1048576.0;

inline LogOddsFx toFixed(double l)
{
	const double s = std::clamp(l * kLogOddsScale, -2.0e9, 2.0e9);
	return static_cast<LogOddsFx>(std::llround(s));
}
inline double fromFixed(LogOddsFx l)
{
	return l / kLogOddsScale;
}

/** max(l - k d, lo): k per-frame decays of d >= 0 with the lower clamp lo,
 * in one step (exact: integers). */
inline LogOddsFx decayFixed(LogOddsFx l, uint64_t k, LogOddsFx d, LogOddsFx lo)
{
	const int64_t v =
	    int64_t(l) - int64_t(std::min<uint64_t>(k, 1u << 31)) * int64_t(d);
	return static_cast<LogOddsFx>(std::max<int64_t>(v, lo));
}

}  // namespace bims::maps
