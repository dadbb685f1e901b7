// Timestamp association between two sorted lists of stamps, as the TUM RGB-D
// benchmark tools do (associate.py, evaluate_rpe.py).
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace bims::eval
{
/** Index pairs (i into \a a, j into \b b). */
using IndexPairs = std::vector<std::pair<size_t, size_t>>;

/** Greedy one-to-one association of TUM's associate.py: every pair with
 * |a_i - (b_j + offset)| < maxDifference is a candidate; candidates are taken
 * in increasing order of that difference, each stamp used at most once. The
 * result is sorted by i. Both inputs must be sorted ascending [s].
 * Complexity O((n+m) k log) where k is the number of candidates per stamp. */
IndexPairs associateGreedy(const std::vector<double>& a,
                           const std::vector<double>& b, double maxDifference,
                           double offset = 0.0);

/** Index of the element of sorted \a v closest to \a t (ties: the lower
 * index). \a v must not be empty. */
size_t closestIndex(const std::vector<double>& v, double t);

}  // namespace bims::eval
