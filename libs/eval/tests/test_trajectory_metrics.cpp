// ATE and RPE on hand-computed examples (values derived in the comments).
#include <bims/eval/trajectory_metrics.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cstdio>

#include <cmath>
#include <tuple>

using bims::StampedPose;
using bims::Trajectory;
using mrpt::poses::CPose3D;
namespace ev = bims::eval;

namespace
{
// Unit square in z = 0, stamps 0..3 s, identity rotations.
Trajectory squareGt()
{
	const double xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
	Trajectory t;
	for (int k = 0; k < 4; k++)
		t.push_back({double(k), CPose3D(xy[k][0], xy[k][1], 0, 0, 0, 0)});
	return t;
}
}  // namespace

TEST(Association, GreedyNearestWithinMaxDifference)
{
	// a: 0 1 2 3; b: 0.015 0.018 1.005 2.5 3.0
	const std::vector<double> a = {0, 1, 2, 3},
	                          b = {0.015, 0.018, 1.005, 2.5, 3.0};
	const auto p = ev::associateGreedy(a, b, 0.02);
	ASSERT_EQ(p.size(), 3u);
	EXPECT_EQ(p[0], std::make_pair(size_t(0), size_t(0)));  // 0.015 < 0.018
	EXPECT_EQ(p[1], std::make_pair(size_t(1), size_t(2)));
	EXPECT_EQ(p[2], std::make_pair(size_t(3), size_t(4)));
	EXPECT_EQ(ev::closestIndex(b, 2.7), 3u);
	EXPECT_EQ(ev::closestIndex(b, -5), 0u);
	EXPECT_EQ(ev::closestIndex(b, 9), 4u);
}

TEST(Ate, HandComputedSquareWithZOffsets)
{
	// EST = T * (GT + d_k), d_k = (0, 0, +-0.1) alternating. The offsets have
	// zero mean and no correlation with the square, so the best alignment is
	// exactly T^-1 and every error is 0.1 m: RMSE = mean = 0.1.
	const Trajectory gt = squareGt();
	const CPose3D T(5, -2, 1, 0.7, 0.2, -0.3);
	Trajectory est;
	for (int k = 0; k < 4; k++)
	{
		const double dz = (k % 2 == 0) ? 0.1 : -0.1;
		const CPose3D p(gt[k].T_WC.x(), gt[k].T_WC.y(), dz, 0.1 * k, 0, 0);
		// Stamps 10 ms late (within TUM's 0.02 s).
		est.push_back({gt[k].t + 0.01, T + p});
	}
	est.push_back({50.0, CPose3D()});  // no partner: ignored
	const auto r = ev::computeAte(gt, est);
	ASSERT_EQ(r.pairs.size(), 4u);
	EXPECT_NEAR(r.stats.rmse, 0.1, 1e-9);
	EXPECT_NEAR(r.stats.mean, 0.1, 1e-9);
	EXPECT_NEAR(r.stats.max, 0.1, 1e-9);
	const CPose3D I = r.T_alignment + T;  // should be identity
	EXPECT_LT(I.translation().norm(), 1e-9);
	EXPECT_LT(std::abs(I.yaw()) + std::abs(I.pitch()) + std::abs(I.roll()),
	          1e-9);
}

TEST(Ate, OneOutlierHandComputed)
{
	// GT: points (0,0,0),(1,0,0),(2,0,0),(3,0,0); EST the same but the last
	// point at z = 0.4. Planar Procrustes in x-z: centred EST e' and GT g'
	// give sum(e'.g') = 5, sum(e' x g') = -0.6, sum|e'|^2 = 5.12,
	// sum|g'|^2 = 5, so the minimal squared residual is
	// 5.12 + 5 - 2 sqrt(5^2 + 0.6^2) and RMSE = sqrt(that / 4) = 0.109837.
	Trajectory gt, est;
	for (int k = 0; k < 4; k++)
	{
		gt.push_back({double(k), CPose3D(k, 0, 0, 0, 0, 0)});
		est.push_back({double(k), CPose3D(k, 0, k == 3 ? 0.4 : 0, 0, 0, 0)});
	}
	const auto r = ev::computeAte(gt, est);
	const double expected = std::sqrt((10.12 - 2 * std::sqrt(25.36)) / 4);
	EXPECT_NEAR(r.stats.rmse, expected, 1e-9);
	EXPECT_NEAR(expected, 0.109837, 1e-6);
	// The alignment rotates by atan(0.6 / 5) about y.
	EXPECT_NEAR(std::abs(r.T_alignment.pitch()), std::atan2(0.6, 5.0), 1e-9);
}

TEST(Ate, BadInputIsAnError)
{
	const Trajectory gt = squareGt();
	EXPECT_THROW(ev::computeAte(gt, Trajectory{}), std::invalid_argument);
	EXPECT_THROW(ev::computeAte(Trajectory{}, gt), std::invalid_argument);
	Trajectory late = gt;
	for (auto& p : late) p.t += 100;
	try
	{
		ev::computeAte(gt, late);
		FAIL();
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("no time overlap"),
		          std::string::npos);
	}
	// issue 39: with a time offset the estimate's span is given as the
	// association sees it, shifted
	ev::AteOptions shifted;
	shifted.timeOffset = 50;
	try
	{
		ev::computeAte(gt, late, shifted);
		FAIL();
	}
	catch (const std::invalid_argument& e)
	{
		const std::string what = e.what();
		const double t0 = late.front().t + 50, t1 = late.back().t + 50;
		char want[96];
		std::snprintf(want, sizeof(want),
		              "[%.3f, %.3f] s with the time offset +50.000 s", t0, t1);
		EXPECT_NE(what.find(want), std::string::npos) << what;
	}
	Trajectory two(gt.begin(), gt.begin() + 2);
	EXPECT_THROW(ev::computeAte(gt, two), std::invalid_argument);
}

TEST(Rpe, TranslationScaleErrorPerSecond)
{
	// GT moves along x at 1 m/s, EST at 1.1 m/s, poses every 0.5 s for 3 s.
	// delta = 1 s: pairs i -> i+2 except those ending on the last pose
	// (i = 0..3): each error 0.1 m over 1 s -> 0.1 m/s.
	Trajectory gt, est;
	for (int k = 0; k <= 6; k++)
	{
		const double t = 0.5 * k;
		gt.push_back({t, CPose3D(t, 0, 0, 0, 0, 0)});
		est.push_back({t, CPose3D(1.1 * t, 0, 0, 0, 0, 0)});
	}
	const auto r = ev::computeRpe(gt, est);
	ASSERT_EQ(r.pairs.size(), 4u);
	EXPECT_EQ(r.pairs[0], std::make_pair(size_t(0), size_t(2)));
	EXPECT_NEAR(r.trans.rmse, 0.1, 1e-9);
	EXPECT_NEAR(r.rot.rmse, 0.0, 1e-6);
	// delta = 0.5 s: error 0.05 m per 0.5 s = still 0.1 m/s.
	ev::RpeOptions o;
	o.delta = 0.5;
	const auto r2 = ev::computeRpe(gt, est, o);
	EXPECT_EQ(r2.pairs.size(), 5u);
	EXPECT_NEAR(r2.trans.rmse, 0.1, 1e-9);
}

TEST(Rpe, RotationRateErrorInDegreesPerSecond)
{
	// GT static; EST spins in place at 10 deg/s about z: every relative
	// error is a pure 10 deg rotation per second.
	Trajectory gt, est;
	for (int k = 0; k <= 40; k++)
	{
		const double t = 0.1 * k;
		gt.push_back({t, CPose3D()});
		est.push_back({t, CPose3D(0, 0, 0, mrpt::DEG2RAD(10.0 * t), 0, 0)});
	}
	const auto r = ev::computeRpe(gt, est);
	EXPECT_EQ(r.pairs.size(), 30u);  // i = 0..29 (j = i + 10 < 40)
	EXPECT_NEAR(r.rot.rmse, 10.0, 1e-6);
	EXPECT_NEAR(r.rot.max, 10.0, 1e-6);
	EXPECT_NEAR(r.trans.rmse, 0.0, 1e-9);
}

TEST(Rpe, PosesOfAnotherBodyAreFlaggedByTheirDisplacements)
{
	// A camera walking a circle of 1 m radius in 8 s while turning; the
	// "ground truth" is that of a body rigidly attached to it with a large
	// rotation and a small lever (as Bonn's motion-capture marker is), and
	// once the camera's own.
	Trajectory cam, marker;
	const CPose3D X(0.011, -0.01, 0.011, mrpt::DEG2RAD(100.0),
	                mrpt::DEG2RAD(30.0), mrpt::DEG2RAD(-40.0));
	for (int k = 0; k <= 240; k++)
	{
		const double t = k / 30.0, a = 2 * M_PI * t / 8;
		const CPose3D T(std::cos(a), std::sin(a), 0.1 * std::sin(3 * a),
		                a + 0.3 * std::sin(2 * a), 0.1 * std::cos(a), 0);
		cam.push_back({t, T});
		marker.push_back({t, T + X});
	}
	const auto judge = [](const Trajectory& gt, const Trajectory& est)
	{
		const auto ate = ev::computeAte(gt, est);
		const auto rpe = ev::computeRpe(gt, est);
		const auto disp = ev::displacementErrors(gt, est, rpe, ate);
		return std::make_tuple(ev::orientationsDisagreeWithPositions(
		                           rpe.trans, disp, ate.stats, 1.0),
		                       ate.stats.rmse, rpe.trans.rmse, disp.rmse);
	};
	const auto [flagged, ate, rpe, disp] = judge(marker, cam);
	EXPECT_TRUE(flagged) << "ate " << ate << " rpe " << rpe << " disp " << disp;
	EXPECT_LT(ate, 0.02);
	EXPECT_GT(rpe, 10 * disp);
	// the camera's own poses, with 5 mm of noise: not flagged
	Trajectory noisy = cam;
	for (size_t k = 0; k < noisy.size(); k++)
		noisy[k].T_WC =
		    noisy[k].T_WC + CPose3D(0.005 * std::sin(7.0 * k),
		                            0.005 * std::cos(3.0 * k), 0,
		                            0.002 * std::sin(5.0 * k), 0, 0);
	EXPECT_FALSE(std::get<0>(judge(cam, noisy)));
	EXPECT_FALSE(std::get<0>(judge(cam, cam)));
}

TEST(Rpe, NoOverlapIsAnError)
{
	Trajectory gt, est;
	for (int k = 0; k <= 40; k++)
	{
		gt.push_back({0.1 * k, CPose3D()});
		est.push_back({1000 + 0.1 * k, CPose3D()});
	}
	EXPECT_THROW(ev::computeRpe(gt, est), std::invalid_argument);
	EXPECT_THROW(ev::computeRpe(gt, Trajectory{}), std::invalid_argument);
}

TEST(TrajectoryReport, JsonHasTheFigures)
{
	ev::TrajectoryReport rep;
	rep.gtPath = "g\"t.txt";
	rep.ate.stats.rmse = 0.25;
	const auto j = bims::jsonText(rep.toJson());
	EXPECT_NE(j.find("\"rmse\": 0.25"), std::string::npos) << j;
	EXPECT_NE(j.find("g\\\"t.txt"), std::string::npos) << j;
}

namespace
{
// A camera walking along x at 0.5 m/s and turning, 30 Hz for 2 s; the
// estimate is the same motion in another world (T_WeWg), 4 ms late, with
// every pose from frame 20 on shifted by 5 cm along the estimate's world y
// (one jump) and from frame 40 on by 2 cm more along its z (a smaller one).
constexpr double kFps = 30;
Trajectory walkingGt()
{
	Trajectory gt;
	for (int k = 0; k <= 60; k++)
	{
		const double t = 100 + k / kFps;
		gt.push_back({t, CPose3D(0.5 * (t - 100), 0.3, 1.2, 0.4 * std::sin(t),
		                         0.1 * std::cos(2 * t), 0.05)});
	}
	return gt;
}
const CPose3D T_WeWg(2, -1, 0.5, 1.1, -0.2, 0.3);
Trajectory estimateOf(const Trajectory& gt, double jump20, double jump40)
{
	Trajectory est;
	for (size_t k = 0; k < gt.size(); k++)
	{
		CPose3D p = T_WeWg + gt[k].T_WC;
		if (k >= 20) p.y_incr(jump20);
		if (k >= 40) p.z_incr(jump40);
		est.push_back({gt[k].t + 0.004, p});
	}
	return est;
}
}  // namespace

TEST(Jumps, OneInjectedJumpGivesItsSizeFrameCountAndSpeed)
{
	const Trajectory gt = walkingGt();
	const Trajectory est = estimateOf(gt, 0.05, 0.02);
	const auto ate = ev::computeAte(gt, est);
	ASSERT_EQ(ate.pairs.size(), gt.size());
	const auto j = ev::computeJumps(gt, est, ate.pairs);
	ASSERT_EQ(j.transErrors.size(), 60u);
	// the shift, whatever the frames' rotations: |R_E19^T d| = |d|
	EXPECT_NEAR(j.stats.max, 0.05, 1e-9);
	EXPECT_EQ(j.maxEstIndex, 20u);
	EXPECT_DOUBLE_EQ(j.maxTime, est[20].t);
	EXPECT_NEAR(j.transErrors[39], 0.02, 1e-9);  // frame 40: under 3 cm
	EXPECT_EQ(j.framesOverJump, 1u);
	for (size_t k = 0; k < j.transErrors.size(); k++)
	{
		if (k != 19 && k != 39)
		{
			EXPECT_LT(j.transErrors[k], 1e-9) << k;
		}
	}
	// 0.5 m/s along the reference's x, plus 5 cm along the estimate's y
	// within one frame
	const auto R = T_WeWg.getRotationMatrix().asEigen();
	const Eigen::Vector3d step =
	    R * Eigen::Vector3d(0.5 / kFps, 0, 0) + Eigen::Vector3d(0, 0.05, 0);
	EXPECT_NEAR(j.maxSpeed, step.norm() * kFps, 1e-6);
	EXPECT_GT(j.maxSpeed, 1.0);
	EXPECT_EQ(j.maxSpeedEstIndex, 20u);
	EXPECT_DOUBLE_EQ(j.maxSpeedTime, est[20].t);
	EXPECT_NEAR(j.refSpeedAtMax, 0.5, 1e-6);
	// a lower threshold counts the smaller jump too
	EXPECT_EQ(ev::computeJumps(gt, est, ate.pairs, {0.01}).framesOverJump, 2u);
	EXPECT_THROW(ev::computeJumps(gt, est, ate.pairs, {-1}),
	             std::invalid_argument);
	EXPECT_THROW(ev::computeJumps(gt, est, {ate.pairs[0]}),
	             std::invalid_argument);
}

TEST(Jumps, ACleanTrajectoryHasNoJumpAndTheReferencesSpeed)
{
	const Trajectory gt = walkingGt();
	const Trajectory est = estimateOf(gt, 0, 0);
	const auto j = ev::computeJumps(gt, est, ev::computeAte(gt, est).pairs);
	EXPECT_LT(j.stats.max, 1e-9);
	EXPECT_EQ(j.framesOverJump, 0u);
	EXPECT_NEAR(j.maxSpeed, 0.5, 1e-6);
	EXPECT_NEAR(j.refSpeedAtMax, 0.5, 1e-6);
}
