// Closed-form cell updates of the three tiers (paper eqs. 3, 4, 9 in the
// exact reading of docs/model.md). Pure functions in double precision and in
// the log domain (lambda^n overflows a double for n in the hundreds). The
// grids quantise their results; these are the reference the oracle tests
// compare with the enumerated joint distributions.
#pragma once

#include <cstdint>

namespace bims::maps
{
/** log(exp(a) + exp(b)) without overflow. */
double logAddExp(double a, double b);
/** Log-odds of a probability, log(p / (1 - p)). */
double logit(double p);
/** Probability of a log-odds value, 1 / (1 + exp(-l)). */
double sigmoid(double l);

/** Tier 0/1: log-odds added by a hit cell with n >= 1 readings,
 * log(((1 - p_miss) lambda^n + p_miss) / p_miss). */
double hitLogOdds(double pMiss, double logLambda, uint32_t n);

/** Tier 0: log-odds added by a cell with no reading (always negative),
 * -log(2 - p_miss). */
double missLogOdds(double pMiss);

/** Tier 0 posterior log-odds (unclamped) from prior log-odds \a lPrior and n
 * readings (n = 0: miss). */
double occupancyPosterior(double lPrior, double pMiss, double logLambda,
                          uint32_t n);

/** Tier 1 prior of I from the previous occupancy O- (log-odds):
 * q = (1 - p-) (1 - eps) + p- eps, returned as log-odds. */
double backgroundPriorLogOdds(double lOccPrev, double eps);

/** Tier 1 posterior log-odds of I for a hit cell with n readings. */
double backgroundPosterior(double lOccPrev, double eps, double pMiss,
                           double logLambda, uint32_t n);

/** Tier 2 posterior log-odds of I for a hit cell with k Diff and l notDiff
 * readings, from the tier-1 posterior log-odds \a lI. \a veto selects the
 * literal reading of Diff readings (docs/model.md). */
double flowPosterior(double lI, double tau, double pMiss, double logFlowLambda,
                     uint32_t k, uint32_t l, bool veto);

}  // namespace bims::maps
