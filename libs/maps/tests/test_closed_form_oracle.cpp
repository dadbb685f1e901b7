// Oracle tests (docs/model.md, "What must prove it"): for each tier, the
// joint distribution of the paper's decomposition is enumerated over all
// hidden binary variables with the model's tables, marginalised and
// normalised here, independently of the production code, and compared with
// the production closed forms over thousands of random parameters/counts.
#include <bims/maps/closed_form.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace bims::maps;

namespace
{
double powLoop(double x, int n)
{
	double r = 1;
	for (int i = 0; i < n; ++i) r *= x;
	return r;
}

// ---- Tier 0: P(O) P(D) P(Z_C | O, D) prod_i P(r_i | O, D) ----------------
double oracleTier0(double p, double pMiss, double lambda, int n)
{
	double joint[2] = {0, 0};
	const bool hit = n > 0;
	for (int O = 0; O < 2; ++O)
		for (int D = 0; D < 2; ++D)
		{
			const double pO = O ? p : 1 - p;
			const double pD = D ? 1 - pMiss : pMiss;
			double pZ = 0.5;  // P(Z_C | O, D), uniform except for O=0, D=1
			if (O == 0 && D == 1) pZ = hit ? 0 : 1;
			double pr = 1;  // readings: Dirac (lambda) if detected, else 1
			for (int i = 0; i < n; ++i) pr *= D == 1 ? lambda : 1;
			joint[O] += pO * pD * pZ * pr;
		}
	return joint[1] / (joint[0] + joint[1]);
}

// ---- Tier 1: P(O-) P(I | O-) P(D) P(Z_C | I, D) prod P(r_i | I, D) -------
double oracleTier1(double pPrev, double eps, double pMiss, double lambda, int n)
{
	double joint[2] = {0, 0};
	for (int Op = 0; Op < 2; ++Op)
		for (int I = 0; I < 2; ++I)
			for (int D = 0; D < 2; ++D)
			{
				const double pOp = Op ? pPrev : 1 - pPrev;
				const double pI1 = Op ? eps : 1 - eps;
				const double pI = I ? pI1 : 1 - pI1;
				const double pD = D ? 1 - pMiss : pMiss;
				double pZ = 0.5;
				if (I == 0 && D == 1) pZ = n > 0 ? 0 : 1;
				const double pr = D == 1 ? powLoop(lambda, n) : 1;
				joint[I] += pOp * pI * pD * pZ * pr;
			}
	return joint[1] / (joint[0] + joint[1]);
}

// ---- Tier 2: P(I) P(Diff_C | I) P(D) prod P(reading | Diff_C, D) ---------
double oracleTier2(double pI, double tau, double pMiss, double lambda, int k,
                   int l, bool veto)
{
	double joint[2] = {0, 0};
	for (int I = 0; I < 2; ++I)
		for (int Dc = 0; Dc < 2; ++Dc)
			for (int D = 0; D < 2; ++D)
			{
				const double pIv = I ? pI : 1 - pI;
				const double pDc = Dc == I ? 1 - tau : tau;
				const double pD = D ? 1 - pMiss : pMiss;
				double pr = 1;
				for (int i = 0; i < k; ++i)  // Diff readings
					pr *= (D == 1 && (veto || Dc == 1)) ? lambda : 1;
				for (int i = 0; i < l; ++i)  // notDiff readings
					pr *= (D == 1 && Dc == 0) ? lambda : 1;
				joint[I] += pIv * pDc * pD * pr;
			}
	return joint[1] / (joint[0] + joint[1]);
}

struct Rand
{
	std::mt19937_64 g{20121002};
	double uni(double a, double b)
	{
		return std::uniform_real_distribution<double>(a, b)(g);
	}
	int integer(int a, int b)
	{
		return std::uniform_int_distribution<int>(a, b)(g);
	}
};
}  // namespace

TEST(ClosedFormOracle, Tier0MatchesEnumeratedJoint)
{
	Rand r;
	for (int it = 0; it < 5000; ++it)
	{
		const double p = r.uni(0.001, 0.999), pm = r.uni(0.01, 0.5);
		const double lambda = it % 4 == 0 ? 1.0 : r.uni(1, 8);
		const int n = r.integer(0, 30);
		const double want = oracleTier0(p, pm, lambda, n);
		const double got =
		    sigmoid(occupancyPosterior(logit(p), pm, std::log(lambda), n));
		ASSERT_NEAR(got, want, 1e-9)
		    << "p=" << p << " pm=" << pm << " lambda=" << lambda << " n=" << n;
	}
}

TEST(ClosedFormOracle, Tier1MatchesEnumeratedJoint)
{
	Rand r;
	for (int it = 0; it < 5000; ++it)
	{
		const double pp = r.uni(0.001, 0.999), eps = r.uni(0.001, 0.49);
		const double pm = r.uni(0.01, 0.5);
		const double lambda = it % 4 == 0 ? 1.0 : r.uni(1, 8);
		const int n = r.integer(1, 30);
		const double want = oracleTier1(pp, eps, pm, lambda, n);
		const double got = sigmoid(
		    backgroundPosterior(logit(pp), eps, pm, std::log(lambda), n));
		ASSERT_NEAR(got, want, 1e-9)
		    << "p-=" << pp << " eps=" << eps << " pm=" << pm << " n=" << n;
	}
}

TEST(ClosedFormOracle, Tier2MatchesEnumeratedJointBothReadings)
{
	Rand r;
	for (int it = 0; it < 5000; ++it)
	{
		const bool veto = it % 2;
		const double pI = r.uni(0.001, 0.999), tau = r.uni(0.001, 0.49);
		const double pm = r.uni(0.01, 0.5), lambda = r.uni(1.01, 8);
		const int k = r.integer(0, 25), l = r.integer(0, 25);
		const double want = oracleTier2(pI, tau, pm, lambda, k, l, veto);
		const double got = sigmoid(
		    flowPosterior(logit(pI), tau, pm, std::log(lambda), k, l, veto));
		ASSERT_NEAR(got, want, 1e-9)
		    << "k=" << k << " l=" << l << " veto=" << veto;
	}
}

TEST(ClosedFormOracle, LogDomainSurvivesHugeCounts)
{
	// lambda^n overflows a double for n in the hundreds; the log-domain
	// forms must stay finite and monotone.
	double prev = 0;
	for (uint32_t n : {1u, 10u, 100u, 1000u, 100000u})
	{
		const double h = hitLogOdds(0.1, std::log(50.0), n);
		EXPECT_TRUE(std::isfinite(h));
		EXPECT_GT(h, prev);
		prev = h;
	}
	const double l =
	    flowPosterior(0.3, 0.05, 0.1, std::log(4.0), 5000, 3, false);
	EXPECT_NEAR(l, 0.3 + std::log(0.95 / 0.05), 1e-9);  // saturates at tau
	// lambda = 1: a reading carries no evidence beyond the hit itself.
	EXPECT_NEAR(hitLogOdds(0.1, 0, 1), std::log(10.0), 1e-12);
	EXPECT_NEAR(hitLogOdds(0.1, 0, 500), std::log(10.0), 1e-12);
	EXPECT_NEAR(missLogOdds(0.1), -std::log(1.9), 1e-15);
}

TEST(ClosedFormOracle, VetoCannotRaiseMotionBelief)
{
	// Literal reading: only consistent flow carries evidence.
	for (int k = 0; k < 10; ++k)
		EXPECT_LE(flowPosterior(0.0, 0.1, 0.1, std::log(3.0), k, 0, true),
		          1e-12);
	EXPECT_GT(flowPosterior(0.0, 0.1, 0.1, std::log(3.0), 5, 0, false), 1.0);
}
