// Closed forms of docs/model.md, in the log domain.
#include <bims/maps/closed_form.h>

#include <algorithm>
#include <cmath>

namespace bims::maps
{
double logAddExp(double a, double b)
{
	const double m = std::max(a, b);
	if (m == -INFINITY) return -INFINITY;
	return m + std::log1p(std::exp(std::min(a, b) - m));
}

double logit(double p)
{
	return std::log(p) - std::log1p(-p);
}

double sigmoid(double l)
{
	return l >= 0 ? 1 / (1 + std::exp(-l)) : std::exp(l) / (1 + std::exp(l));
}

// log(((1 - Pm) lambda^n + Pm) / Pm)
double hitLogOdds(double pMiss, double logLambda, uint32_t n)
{
	const double a = std::log1p(-pMiss) + double(n) * logLambda;
	const double b = std::log(pMiss);
	return logAddExp(a, b) - b;
}

double missLogOdds(double pMiss)
{
	return -std::log(2 - pMiss);
}

double occupancyPosterior(double lPrior, double pMiss, double logLambda,
                          uint32_t n)
{
	return lPrior +
	       (n > 0 ? hitLogOdds(pMiss, logLambda, n) : missLogOdds(pMiss));
}

// q = (1-p)(1-eps) + p eps; 1-q = (1-p) eps + p (1-eps). In logs, with
// log p = -log(1+e^-l), log(1-p) = -log(1+e^l).
double backgroundPriorLogOdds(double lOccPrev, double eps)
{
	const double lp = -logAddExp(0, -lOccPrev);
	const double l1p = -logAddExp(0, lOccPrev);
	const double le = std::log(eps), l1e = std::log1p(-eps);
	return logAddExp(l1p + l1e, lp + le) - logAddExp(l1p + le, lp + l1e);
}

double backgroundPosterior(double lOccPrev, double eps, double pMiss,
                           double logLambda, uint32_t n)
{
	return occupancyPosterior(backgroundPriorLogOdds(lOccPrev, eps), pMiss,
	                          logLambda, n);
}

double flowPosterior(double lI, double tau, double pMiss, double logFlowLambda,
                     uint32_t k, uint32_t l, bool veto)
{
	const double a = std::log1p(-pMiss), b = std::log(pMiss);
	const double logL1 = logAddExp(a + double(k) * logFlowLambda, b);
	const double logL0 =
	    logAddExp(a + double(veto ? k + l : l) * logFlowLambda, b);
	const double lt = std::log(tau), l1t = std::log1p(-tau);
	return lI + logAddExp(l1t + logL1, lt + logL0) -
	       logAddExp(lt + logL1, l1t + logL0);
}

}  // namespace bims::maps
