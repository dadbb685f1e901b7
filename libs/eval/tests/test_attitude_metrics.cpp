// Attitude metrics (tilt, heading drift) on trajectories built with a known
// tilt and a known heading drift, in worlds with different up axes.
#include <bims/eval/attitude_metrics.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

using namespace bims::eval;

namespace
{
Eigen::Matrix3d rot(const Eigen::Vector3d& axis, double a)
{
	return Eigen::AngleAxisd(a, axis.normalized()).toRotationMatrix();
}
mrpt::poses::CPose3D pose(const Eigen::Matrix3d& R)
{
	mrpt::math::CMatrixDouble33 m;
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) m(i, j) = R(i, j);
	return mrpt::poses::CPose3D::FromRotationAndTranslation(
	    m, mrpt::math::CVectorFixedDouble<3>());
}
constexpr double kDeg = M_PI / 180;
}  // namespace

TEST(AttitudeError, KnownTiltAndHeadingDriftAcrossWorldsWithOtherUpAxes)
{
	// reference: ARKit-like world, y up; estimate: bims's, z up
	const Eigen::Vector3d upR = Eigen::Vector3d::UnitY();
	const Eigen::Matrix3d R_WeWr = rot(Eigen::Vector3d::UnitX(), M_PI / 2);
	ASSERT_TRUE((R_WeWr * upR).isApprox(Eigen::Vector3d::UnitZ()));
	const double tilt = 0.7 * kDeg, rate = 3 * kDeg / 60;  // 3 deg/min
	const Eigen::Matrix3d tiltR = rot(Eigen::Vector3d(1, 0, 0.4), tilt);
	bims::Trajectory ref, est;
	for (int k = 0; k <= 300; k++)
	{
		const double t = 100 + k * 0.05;
		const Eigen::Matrix3d Rr = rot(Eigen::Vector3d(0.2, 1, 0.3), 0.01 * k) *
		                           rot(Eigen::Vector3d(1, 0, 0), 0.3);
		const Eigen::Matrix3d drift = rot(upR, rate * (t - 100));
		ref.push_back({t, pose(Rr)});
		est.push_back(
		    {t + 0.001, pose(R_WeWr * tiltR * drift.transpose() * Rr)});
	}
	AttitudeOptions o;
	o.upRef = upR;
	const auto r = computeAttitudeError(ref, est, o);
	ASSERT_EQ(r.pairs.size(), 301u);
	// tiltR's axis is not horizontal: its tilt is the angle it turns up by
	const Eigen::Vector3d u = tiltR.transpose() * upR;
	const double expTilt = std::acos(u.dot(upR)) / kDeg;
	EXPECT_NEAR(r.tilt.rmse, expTilt, 1e-6);
	EXPECT_NEAR(r.tilt.max, expTilt, 1e-6);
	EXPECT_NEAR(r.heading_drift_deg_min, 3.0, 1e-6);
	EXPECT_NEAR(r.heading_max_abs_deg, 3.0 * 15 / 60, 1e-6);
	EXPECT_NEAR(r.span_s, 15, 1e-9);
	// the wrong up axis for the estimate is seen as a large tilt
	o.upEst = Eigen::Vector3d::UnitY();
	EXPECT_GT(computeAttitudeError(ref, est, o).tilt.rmse, 45);
	// skipping the first 10 s leaves 5 s of pairs
	o.upEst = Eigen::Vector3d::UnitZ();
	o.skip_s = 10;
	const auto s = computeAttitudeError(ref, est, o);
	EXPECT_NEAR(s.span_s, 5, 0.05 + 1e-9);
	EXPECT_NEAR(s.heading_drift_deg_min, 3.0, 1e-6);
}

TEST(AttitudeError, HeadingIsUnwrappedPastHalfATurn)
{
	const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
	bims::Trajectory ref, est;
	for (int k = 0; k <= 100; k++)
	{
		const double t = k * 0.1;
		const Eigen::Matrix3d Rr = rot(Eigen::Vector3d(1, 0, 0), -M_PI / 2);
		ref.push_back({t, pose(Rr)});
		// 36 deg/s: 360 deg over the 10 s
		est.push_back({t, pose(rot(up, -36 * kDeg * t) * Rr)});
	}
	const auto r = computeAttitudeError(ref, est);
	EXPECT_NEAR(r.heading_deg.back(), 360, 1e-6);
	EXPECT_NEAR(r.heading_drift_deg_min, 36 * 60, 1e-6);
	EXPECT_NEAR(r.tilt.max, 0, 1e-6);
}

TEST(AttitudeError, BadInputIsAnError)
{
	bims::Trajectory a = {{0, {}}, {1, {}}}, b = {{5, {}}, {6, {}}};
	EXPECT_THROW(computeAttitudeError(a, b), std::invalid_argument);
	AttitudeOptions o;
	o.upRef = Eigen::Vector3d(0, 2, 0);
	EXPECT_THROW(computeAttitudeError(a, a, o), std::invalid_argument);
	EXPECT_THROW(axisFromName("w"), std::invalid_argument);
	EXPECT_TRUE(axisFromName("-y").isApprox(-Eigen::Vector3d::UnitY()));
}
