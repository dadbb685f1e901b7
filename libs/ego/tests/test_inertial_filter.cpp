// InertialFilter (the depth-inertial translation, docs/ego.md): its
// propagation against a known trajectory, the degeneracy analysis, the update
// along constrained and unconstrained directions, the gate, the biases it
// observes and the fall-back where the IMU is missing.
#include <bims/common/so3.h>
#include <bims/ego/inertial_filter.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace bims;
using namespace bims::ego;

namespace
{
const Eigen::Vector3d kG(0, 0, -9.80665);

/** A smooth hand-held motion starting at rest: p(t) = A (1 - cos(w t)) per
 * axis, a rotation about a tilted axis growing as (1 - cos(wr t)). */
struct Motion
{
	Eigen::Vector3d A{0.3, 0.2, 0.1}, w{1.3, 2.1, 1.7};
	double wr = 0.9, ar = 0.6;
	Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 3).normalized();

	Eigen::Vector3d p(double t) const
	{
		return A.array() * (1 - (w.array() * t).cos());
	}
	Eigen::Vector3d a(double t) const
	{
		return A.array() * w.array().square() * (w.array() * t).cos();
	}
	/** turning about two axes, so that every axis of the bias is seen
	 * against gravity */
	Eigen::Matrix3d R_WI(double t) const
	{
		return expSO3(axis * ar * (1 - std::cos(wr * t))) *
		       expSO3(Eigen::Vector3d(0.5 * std::sin(1.4 * t), 0, 0));
	}
	/** The specific force in {I} plus a bias. */
	Eigen::Vector3d f(double t, const Eigen::Vector3d& bias) const
	{
		return R_WI(t).transpose() * (a(t) - kG) + bias;
	}
};

InertialFilter::RotationAt rotationOf(const Motion& m)
{
	return
	    [m](double t) -> std::optional<Eigen::Matrix3d> { return m.R_WI(t); };
}

void feed(InertialFilter& f, const Motion& m, double t0, double t1, double hz,
          const Eigen::Vector3d& bias = Eigen::Vector3d::Zero())
{
	for (double t = t0; t <= t1 + 1e-9; t += 1 / hz)
		f.addAccel(t, m.f(t, bias));
}
}  // namespace

TEST(InertialFilter, PropagationFollowsTheTrajectoryFromTheAccelerometer)
{
	const Motion m;
	InertialParams p;
	p.init_velocity_sigma = 1e-3;
	InertialFilter f(p);
	feed(f, m, 0, 2.0, 200);
	f.initialize(0, m.p(0));
	// 60 frames a second for 1 s without any measurement: dead reckoning
	for (int k = 1; k <= 60; k++)
	{
		const InertialPropagation pr = f.propagate(k / 60.0, rotationOf(m));
		EXPECT_EQ(pr.prior_s, 0) << k;
		EXPECT_GT(pr.samples, 0);
	}
	EXPECT_LT((f.state().p_WC - m.p(1.0)).norm(), 2e-3);
	// the uncertainty grew as the noise density says, not wildly
	const double sigma = std::sqrt(f.state().P.block<3, 3>(0, 0).trace() / 3);
	EXPECT_GT(sigma, 1e-3);
	EXPECT_LT(sigma, 0.5);
}

TEST(InertialFilter, DegeneracyCountsTheDirectionsTheDepthDoesNotPin)
{
	const double s = 0.01;
	EXPECT_EQ(analyseDegeneracy(Eigen::Matrix3d::Identity() * 1e8, s).count, 0);
	const Eigen::Matrix3d wall = Eigen::Vector3d(1e8, 0, 0).asDiagonal();
	const Degeneracy d = analyseDegeneracy(wall, s);
	EXPECT_EQ(d.count, 2);
	// the constrained direction is the wall's normal (the last eigenvector)
	EXPECT_NEAR(std::abs(d.directions.col(2).x()), 1, 1e-9);
	const Eigen::Matrix3d corridor = Eigen::Vector3d(1e8, 1e8, 50).asDiagonal();
	EXPECT_EQ(analyseDegeneracy(corridor, s).count, 1);
	EXPECT_EQ(analyseDegeneracy(Eigen::Matrix3d::Zero(), s).count, 3);
}

TEST(InertialFilter, AlongAWallTheSlipIsRefusedAndTheNormalIsMeasured)
{
	// A blank wall with its normal along x: the alignment pins x to 1 mm and
	// says nothing about y and z, where its solver slipped by 0.2 m. The
	// position takes x from the depth and keeps the inertial y, z (the
	// update remaps the solution: Zhang & Singh).
	const Motion m;
	InertialFilter f(InertialParams{});
	feed(f, m, 0, 1.0, 200);
	f.initialize(0, m.p(0));
	const Eigen::Matrix3d wall =
	    Eigen::Vector3d(1 / (1e-3 * 1e-3), 0, 0).asDiagonal();
	for (int k = 1; k <= 30; k++)
	{
		const double t = k / 60.0;
		f.propagate(t, rotationOf(m));
		Eigen::Vector3d meas = m.p(t);
		meas.y() += 0.2;  // the slip
		const InertialUpdate u = f.update(meas, wall);
		EXPECT_TRUE(u.accepted) << k;
		EXPECT_EQ(u.degeneracy.count, 2);
	}
	const Eigen::Vector3d err = f.state().p_WC - m.p(0.5);
	EXPECT_LT(std::abs(err.x()), 2e-3);
	EXPECT_LT(std::abs(err.y()), 0.01);
	EXPECT_LT(std::abs(err.z()), 0.01);
}

TEST(InertialFilter, AJumpTheImuDidNotFeelIsRefusedByTheGate)
{
	const Motion m;
	InertialFilter f(InertialParams{});
	feed(f, m, 0, 2.0, 200);
	f.initialize(0, m.p(0));
	const Eigen::Matrix3d full = Eigen::Matrix3d::Identity() / (2e-3 * 2e-3);
	for (int k = 1; k <= 60; k++)
	{
		f.propagate(k / 60.0, rotationOf(m));
		ASSERT_TRUE(f.update(m.p(k / 60.0), full).accepted) << k;
	}
	f.propagate(61 / 60.0, rotationOf(m));
	const Eigen::Vector3d before = f.state().p_WC;
	Eigen::Vector3d jump = m.p(61 / 60.0);
	jump.x() += 0.10;  // 6 m/s for one frame
	const InertialUpdate u = f.update(jump, full);
	EXPECT_FALSE(u.accepted);
	EXPECT_GT(u.nis, 100);
	EXPECT_EQ(f.state().p_WC, before);  // nothing changed
	// the truth passes
	EXPECT_TRUE(f.check(m.p(61 / 60.0), full).accepted);
}

TEST(InertialFilter, TheAccelerometerBiasIsObservedWhileThePhoneTurns)
{
	const Motion m;
	const Eigen::Vector3d bias(0.08, -0.05, 0.04);
	// an accelerometer as clean as this one is trusted as such (the
	// default's noise stands for a phone's rotation errors)
	InertialParams p;
	p.acc_noise_density = 0.01;
	InertialFilter f(p);
	feed(f, m, 0, 20.0, 100, bias);
	f.initialize(0, m.p(0));
	std::mt19937 rng(7);
	std::normal_distribution<double> n(0, 2e-3);
	const Eigen::Matrix3d full = Eigen::Matrix3d::Identity() / (2e-3 * 2e-3);
	for (int k = 1; k <= 20 * 30; k++)
	{
		const double t = k / 30.0;
		f.propagate(t, rotationOf(m));
		f.update(m.p(t) + Eigen::Vector3d(n(rng), n(rng), n(rng)), full);
	}
	EXPECT_LT((f.state().b_a - bias).norm(), 0.02) << f.state().b_a.transpose();
	EXPECT_LT((f.state().g_W - kG).norm(), 0.02) << f.state().g_W.transpose();
	EXPECT_LT(
	    (f.state().v_W -
	     (m.A.array() * m.w.array() * (m.w.array() * 20.0).sin()).matrix())
	        .norm(),
	    0.02);
}

TEST(InertialFilter, WithoutSamplesTheMotionPriorCarriesTheInterval)
{
	InertialParams p;
	InertialFilter f(p);
	f.initialize(0, Eigen::Vector3d::Zero());
	// no sample at all: constant velocity (zero) and the hand-held prior
	const InertialPropagation pr =
	    f.propagate(0.5, [](double) { return Eigen::Matrix3d::Identity(); });
	EXPECT_EQ(pr.samples, 0);
	EXPECT_NEAR(pr.prior_s, 0.5, 1e-12);
	EXPECT_TRUE(f.state().p_WC.isZero());
	// variance of a random walk in velocity, integrated: q^2 t^3 / 3 more
	// than the initial velocity's
	const double t = 0.5, q = p.motion_accel_density,
	             sv = p.init_velocity_sigma;
	EXPECT_NEAR(f.state().P(0, 0), sv * sv * t * t + q * q * t * t * t / 3,
	            1e-9);
}

TEST(InertialFilter, AGapIsBridgedByThePriorAndTheSamplesAfterItAreUsed)
{
	const Motion m;
	InertialFilter f(InertialParams{});
	for (double t = 0; t <= 2.0; t += 0.01)
		if (t < 0.5 || t > 1.0) f.addAccel(t, m.f(t, Eigen::Vector3d::Zero()));
	f.initialize(0, m.p(0));
	double prior = 0;
	int samples = 0;
	for (int k = 1; k <= 120; k++)
	{
		const InertialPropagation pr = f.propagate(k / 60.0, rotationOf(m));
		prior += pr.prior_s;
		if (k > 62) samples += pr.samples;  // after the gap
	}
	EXPECT_NEAR(prior, 0.5, 0.03);
	EXPECT_GT(samples, 50);
	EXPECT_TRUE(f.state().p_WC.allFinite());
}

TEST(InertialFilter, SaturatedSamplesAreLeftOut)
{
	InertialParams p;
	p.accel_range_ms2 = 20;
	InertialFilter f(p);
	for (double t = 0; t <= 0.2; t += 0.01)
		f.addAccel(t,
		           Eigen::Vector3d(0, 0, t > 0.05 && t < 0.1 ? 20 : 9.80665));
	f.initialize(0, Eigen::Vector3d::Zero());
	const InertialPropagation pr =
	    f.propagate(0.2, [](double) { return Eigen::Matrix3d::Identity(); });
	EXPECT_TRUE(pr.saturated);
	EXPECT_GT(pr.prior_s, 0.03);
	// what was integrated was at rest: no velocity from the clipped samples
	EXPECT_LT(f.state().v_W.norm(), 1e-6);
}

TEST(InertialFilter, LevellingTurnsTheEstimatedGravityStraightDown)
{
	// gravity 2 deg off the world's -z: the levelling is that 2 deg rotation
	const Eigen::Vector3d g =
	    expSO3(Eigen::Vector3d(2 * M_PI / 180, 0, 0)) * kG +
	    Eigen::Vector3d::Zero();
	const Eigen::Matrix3d R = levellingRotation(g);
	EXPECT_LT((R * g - kG).norm(), 1e-9);
	EXPECT_NEAR(angleSO3(R), 2 * M_PI / 180, 1e-9);
	EXPECT_TRUE(levellingRotation(kG).isApprox(Eigen::Matrix3d::Identity()));
	EXPECT_TRUE(levellingRotation(Eigen::Vector3d::Zero())
	                .isApprox(Eigen::Matrix3d::Identity()));
}
