// Motion models and the IMU model: exact agreement between the IMU and the
// ground-truth poses, and the noise model's statistics.
#include <bims/common/frames.h>
#include <bims/sim/imu.h>
#include <bims/sim/motion.h>
#include <gtest/gtest.h>

#include <cmath>

using namespace bims::sim;

namespace
{
constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d expSO3(const Eigen::Vector3d& w)
{
	const double a = w.norm();
	if (a < 1e-15) return Eigen::Matrix3d::Identity();
	return Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}
double angleDeg(const Eigen::Matrix3d& R)
{
	return std::acos(std::clamp((R.trace() - 1) / 2, -1.0, 1.0)) / kDeg;
}
Eigen::Vector3d gyro(const mrpt::obs::CObservationIMU& o)
{
	using namespace mrpt::obs;
	return {o.get(IMU_WX), o.get(IMU_WY), o.get(IMU_WZ)};
}
Eigen::Vector3d acc(const mrpt::obs::CObservationIMU& o)
{
	using namespace mrpt::obs;
	return {o.get(IMU_X_ACC), o.get(IMU_Y_ACC), o.get(IMU_Z_ACC)};
}
Eigen::Vector3d mag(const mrpt::obs::CObservationIMU& o)
{
	using namespace mrpt::obs;
	return {o.get(IMU_MAG_X), o.get(IMU_MAG_Y), o.get(IMU_MAG_Z)};
}

/** Integrates noiseless gyro samples (2nd-order: mean rate + coning term)
 * and returns the worst attitude error [deg] against the true R_WI. */
double gyroIntegrationErrorDeg(const HandheldMotionParams& mp, double rateHz,
                               double seconds)
{
	const HandheldMotion motion(mp);
	ImuParams p;
	p.rateHz = rateHz;
	p.makeNoiseless();
	p.setR_IC_ypr(-80, 3, -95);  // not exactly the nominal mounting
	ImuSimulator imu(p, 7);
	const Eigen::Matrix3d R_WI0 = motion.at(0).R_WC * p.R_IC.transpose();
	Eigen::Matrix3d R = R_WI0;
	Eigen::Vector3d wPrev = gyro(*imu.sample(motion, 0, 0));
	double worst = 0;
	const int n = int(seconds * rateHz);
	for (int k = 1; k <= n; k++)
	{
		const double t = k / rateHz;
		const Eigen::Vector3d w = gyro(*imu.sample(motion, t, 0));
		const double dt = 1 / rateHz;
		R = R * expSO3(0.5 * (wPrev + w) * dt + wPrev.cross(w) * dt * dt / 12);
		wPrev = w;
		const Eigen::Matrix3d R_true = motion.at(t).R_WC * p.R_IC.transpose();
		worst = std::max(worst, angleDeg(R.transpose() * R_true));
	}
	return worst;
}
}  // namespace

TEST(HandheldMotion, AngularVelocityMatchesFiniteDifferences)
{
	HandheldMotionParams mp;
	mp.rotAmplitudeDeg = {35, 10, 6};
	mp.rotFreqHz = {0.7, 0.9, 1.1};
	const HandheldMotion m(mp);
	const double h = 1e-5;
	for (double t = 0.1; t < 5; t += 0.37)
	{
		const auto k = m.at(t);
		const Eigen::Matrix3d dR =
		    m.at(t - h).R_WC.transpose() * m.at(t + h).R_WC;
		const Eigen::AngleAxisd aa(dR);
		const Eigen::Vector3d wFd = aa.axis() * aa.angle() / (2 * h);
		EXPECT_LT((wFd - k.omega_C).norm(), 1e-6) << "t=" << t;
		const Eigen::Vector3d aFd =
		    (m.at(t + h).v_W - m.at(t - h).v_W) / (2 * h);
		const Eigen::Vector3d vFd =
		    (m.at(t + h).p_WC - m.at(t - h).p_WC) / (2 * h);
		EXPECT_LT((aFd - k.a_W).norm(), 1e-5);
		EXPECT_LT((vFd - k.v_W).norm(), 1e-6);
	}
}

TEST(HandheldMotion, AWalkEasedFromRestStartsStillWithExactDerivatives)
{
	HandheldMotionParams mp;
	mp.velocity = {0.6, -0.2, 0};
	mp.startFromRestS = 0.8;
	const HandheldMotion m(mp);
	const auto k0 = m.at(0);
	EXPECT_LT(k0.v_W.norm(), 1e-12);
	EXPECT_LT(k0.omega_C.norm(), 1e-12);
	EXPECT_LT((k0.p_WC - mp.position).norm(), 1e-12);
	// held still before the start
	EXPECT_LT((m.at(-0.5).p_WC - mp.position).norm(), 1e-12);
	const double h = 1e-5;
	for (double t = 0.05; t < 9; t += 0.41)
	{
		const auto k = m.at(t);
		const Eigen::Matrix3d dR =
		    m.at(t - h).R_WC.transpose() * m.at(t + h).R_WC;
		const Eigen::AngleAxisd aa(dR);
		EXPECT_LT((aa.axis() * aa.angle() / (2 * h) - k.omega_C).norm(), 1e-6)
		    << "t=" << t;
		EXPECT_LT(
		    ((m.at(t + h).p_WC - m.at(t - h).p_WC) / (2 * h) - k.v_W).norm(),
		    1e-6)
		    << "t=" << t;
		EXPECT_LT(
		    ((m.at(t + h).v_W - m.at(t - h).v_W) / (2 * h) - k.a_W).norm(),
		    1e-5)
		    << "t=" << t;
	}
	// after a few time constants: the walk plus the sway, travelled on
	const HandheldMotion still(
	    [&]
	    {
		    HandheldMotionParams q = mp;
		    q.posAmplitude.setZero();
		    return q;
	    }());
	EXPECT_NEAR(still.at(20).v_W.x(), 0.6, 1e-6);
	EXPECT_NEAR(still.at(20).p_WC.y() - mp.position.y(), -0.2 * (20 - 0.8),
	            1e-6);
}

TEST(HandheldMotion, FastRotationPresetPeaksAbove180DegPerSecond)
{
	HandheldMotionParams mp;  // the values of config/sim/fast_rotation.ini
	mp.rotAmplitudeDeg = {35, 10, 6};
	mp.rotFreqHz = {0.7, 0.9, 1.1};
	const HandheldMotion m(mp);
	double peak = 0;
	for (double t = 0; t < 10; t += 0.005)
		peak = std::max(peak, m.at(t).omega_C.norm());
	EXPECT_GT(peak / kDeg, 180.0);
}

TEST(ImuSimulator, NoiselessGyroIntegratesToGroundTruth)
{
	// The paper-like slow motion: < 0.01 deg over 10 s at 100 Hz.
	EXPECT_LT(gyroIntegrationErrorDeg(HandheldMotionParams(), 100, 10), 0.01);
	// Fast rotation (peaks > 180 deg/s): the same at 1 kHz.
	HandheldMotionParams fast;
	fast.rotAmplitudeDeg = {35, 10, 6};
	fast.rotFreqHz = {0.7, 0.9, 1.1};
	EXPECT_LT(gyroIntegrationErrorDeg(fast, 1000, 10), 0.01);
}

TEST(ImuSimulator, NoiselessAccelerometerAtRestReadsGravityInImuFrame)
{
	HandheldMotionParams mp;
	mp.posAmplitude.setZero();
	mp.rotAmplitudeDeg.setZero();
	mp.yprDeg = {30, -20, 10};
	const HandheldMotion motion(mp);
	ImuParams p;
	p.makeNoiseless();
	ImuSimulator imu(p, 1);
	for (double t = 0; t < 2; t += 0.5)
	{
		const auto o = imu.sample(motion, t, 0);
		const Eigen::Matrix3d R_WI = motion.at(t).R_WC * p.R_IC.transpose();
		const Eigen::Vector3d expected =
		    R_WI.transpose() * Eigen::Vector3d(0, 0, bims::kGravity);
		EXPECT_LT((acc(*o) - expected).norm(), 1e-9);
		EXPECT_NEAR(acc(*o).norm(), bims::kGravity, 1e-9);
		EXPECT_LT(gyro(*o).norm(), 1e-12);
	}
	// Level camera, default mounting: {I} z is up, so the z axis reads +g.
	mp.yprDeg = {47, 0, 0};
	ImuSimulator imu2(p, 1);
	const Eigen::Vector3d f = acc(*imu2.sample(HandheldMotion(mp), 0, 0));
	EXPECT_NEAR(f.z(), bims::kGravity, 1e-9);
	EXPECT_NEAR(f.x(), 0, 1e-9);
	EXPECT_NEAR(f.y(), 0, 1e-9);
}

TEST(ImuSimulator, MagnetometerMatchesConfiguredField)
{
	HandheldMotionParams mp;
	mp.posAmplitude.setZero();
	mp.rotAmplitudeDeg.setZero();
	mp.yprDeg = {0, 0, 0};  // IMU axes = world axes with the default R_IC
	ImuParams p;
	p.makeNoiseless();
	p.magField = 0.5;
	p.magDipDeg = 60;
	ImuSimulator imu(p, 3);
	const Eigen::Vector3d m = mag(*imu.sample(HandheldMotion(mp), 0, 0));
	EXPECT_NEAR(m.x(), 0.5 * std::cos(60 * kDeg), 1e-12);
	EXPECT_NEAR(m.y(), 0, 1e-12);
	EXPECT_NEAR(m.z(), -0.5 * std::sin(60 * kDeg), 1e-12);
	// Yawed by 90 deg (facing west = +y): north is now along -y of {I}.
	mp.yprDeg = {90, 0, 0};
	ImuSimulator imu2(p, 3);
	const Eigen::Vector3d m2 = mag(*imu2.sample(HandheldMotion(mp), 0, 0));
	EXPECT_NEAR(m2.y(), -0.5 * std::cos(60 * kDeg), 1e-12);
	EXPECT_NEAR(m2.norm(), 0.5, 1e-12);
}

TEST(ImuSimulator, MagneticDisturbanceOnlyInsideItsRegion)
{
	ImuParams p;
	p.disturbance = true;
	p.disturbanceCenter = {1, 0, 1};
	p.disturbanceRadius = 0.5;
	p.disturbanceField = {0, 0.3, 0};
	const Eigen::Vector3d e = p.earthField_W();
	EXPECT_LT((p.field_W({3, 0, 1}) - e).norm(), 1e-15);
	EXPECT_NEAR((p.field_W({1, 0, 1}) - e).y(), 0.3, 1e-15);
	const double mid = (p.field_W({1.25, 0, 1}) - e).y();
	EXPECT_GT(mid, 0.0);
	EXPECT_LT(mid, 0.3);
}

TEST(ImuSimulator, WhiteNoiseHasConfiguredDensity)
{
	HandheldMotionParams mp;
	mp.posAmplitude.setZero();
	mp.rotAmplitudeDeg.setZero();
	ImuParams p;
	p.makeNoiseless();
	p.gyroNoiseDensity = 1e-3;
	p.accNoiseDensity = 3e-3;
	p.rateHz = 200;
	ImuSimulator imu(p, 11);
	const HandheldMotion motion(mp);
	const int n = 20000;
	double sg = 0, sa = 0, mg = 0;
	ImuParams clean = p;
	clean.makeNoiseless();
	ImuSimulator ref(clean, 11);
	for (int k = 0; k < n; k++)
	{
		const double t = k / p.rateHz;
		const auto o = imu.sample(motion, t, 0);
		const auto r = ref.sample(motion, t, 0);
		const Eigen::Vector3d dg = gyro(*o) - gyro(*r), da = acc(*o) - acc(*r);
		sg += dg.squaredNorm();
		sa += da.squaredNorm();
		mg += dg.sum();
	}
	const double sigG = std::sqrt(sg / (3 * n)), sigA = std::sqrt(sa / (3 * n));
	EXPECT_NEAR(sigG / (1e-3 * std::sqrt(200.0)), 1.0, 0.03);
	EXPECT_NEAR(sigA / (3e-3 * std::sqrt(200.0)), 1.0, 0.03);
	EXPECT_NEAR(mg / (3 * n), 0.0, 4 * sigG / std::sqrt(3.0 * n));
}

TEST(ImuSimulator, BiasRandomWalkGrowsWithSqrtTime)
{
	// Across many seeds the bias change over T seconds has sigma_rw sqrt(T).
	HandheldMotionParams mp;
	const HandheldMotion motion(mp);
	ImuParams p;
	p.makeNoiseless();
	p.gyroBiasRw = 1e-3;
	p.magBiasRw = 2e-3;
	const int seeds = 400;
	double s2 = 0, m2 = 0;
	for (int s = 0; s < seeds; s++)
	{
		ImuSimulator imu(p, uint64_t(s));
		ImuTruth tr;
		for (int k = 0; k <= 400; k++) imu.sample(motion, k / 100.0, 0, &tr);
		s2 += tr.gyroBias.squaredNorm();
		m2 += tr.magBias.squaredNorm();
	}
	const double sigma = std::sqrt(s2 / (3 * seeds));
	EXPECT_NEAR(sigma / (1e-3 * std::sqrt(4.0)), 1.0, 0.08);
	EXPECT_NEAR(std::sqrt(m2 / (3 * seeds)) / (2e-3 * std::sqrt(4.0)), 1.0,
	            0.08);
}

TEST(ImuSimulator, TimeOffsetShiftsTheMeasuredInstant)
{
	const HandheldMotion motion{HandheldMotionParams()};
	ImuParams p;
	p.makeNoiseless();
	p.timeOffsetS = 0.04;
	ImuSimulator imu(p, 1);
	ImuParams p0 = p;
	p0.timeOffsetS = 0;
	ImuSimulator imu0(p0, 1);
	ImuTruth tr;
	const auto o = imu.sample(motion, 1.0, 0, &tr);
	EXPECT_DOUBLE_EQ(tr.tTrue, 0.96);
	const auto o0 = imu0.sample(motion, 0.96, 0);
	EXPECT_LT((gyro(*o) - gyro(*o0)).norm(), 1e-12);
	EXPECT_NEAR(mrpt::Clock::toDouble(o->timestamp), 1.0, 1e-6);
}

TEST(SynthesizeImu, FromTumTrajectoryFollowsTheMotion)
{
	// A 30 Hz trajectory sampled from a known smooth motion: the spline's IMU
	// must be close to the analytic one.
	HandheldMotionParams mp;
	const HandheldMotion motion(mp);
	bims::Trajectory traj;
	for (int k = 0; k <= 150; k++)
	{
		const double t = 1000.0 + k / 30.0;
		const auto km = motion.at(t - 1000.0);
		mrpt::math::CMatrixDouble44 M = mrpt::math::CMatrixDouble44::Identity();
		for (int r = 0; r < 3; r++)
		{
			for (int c = 0; c < 3; c++) M(r, c) = km.R_WC(r, c);
			M(r, 3) = km.p_WC[r];
		}
		traj.push_back({t, mrpt::poses::CPose3D(M)});
	}
	ImuParams p;
	p.makeNoiseless();
	std::vector<ImuTruth> truth;
	const auto obs = synthesizeImu(traj, p, 5, &truth);
	ASSERT_EQ(obs.size(), 501u);  // 5 s at 100 Hz, both ends included
	EXPECT_EQ(obs.front()->sensorLabel, "IMU_SYNTH");
	ImuSimulator ref(p, 5);
	double worstW = 0, worstA = 0;
	for (size_t i = 50; i + 50 < obs.size();
	     i++)  // away from the natural-spline ends
	{
		const double t = mrpt::Clock::toDouble(obs[i]->timestamp);
		const auto r = ref.sample(motion, t, 1000.0);
		worstW = std::max(worstW, (gyro(*obs[i]) - gyro(*r)).norm());
		worstA = std::max(worstA, (acc(*obs[i]) - acc(*r)).norm());
	}
	EXPECT_LT(worstW / kDeg, 0.1);  // deg/s
	EXPECT_LT(worstA, 0.02);        // m/s^2
	bims::Trajectory tooShort(traj.begin(), traj.begin() + 3);
	EXPECT_THROW(synthesizeImu(tooShort, p, 5), std::invalid_argument);
}

TEST(ImuSimulator, OrientationOutputIsTrueAttitudeWhenNoiseless)
{
	const HandheldMotion motion{HandheldMotionParams()};
	ImuParams p;
	p.makeNoiseless();
	p.orientation = true;
	ImuSimulator imu(p, 1);
	for (double t : {0.0, 1.3, 4.2})
	{
		using namespace mrpt::obs;
		const auto o = imu.sample(motion, t, 0);
		ASSERT_TRUE(o->has(IMU_ORI_QUAT_W));
		const Eigen::Quaterniond q(
		    o->get(IMU_ORI_QUAT_W), o->get(IMU_ORI_QUAT_X),
		    o->get(IMU_ORI_QUAT_Y), o->get(IMU_ORI_QUAT_Z));
		const Eigen::Matrix3d R_WI = motion.at(t).R_WC * p.R_IC.transpose();
		EXPECT_LT(angleDeg(q.toRotationMatrix().transpose() * R_WI), 1e-6);
	}
	ImuParams off;
	EXPECT_FALSE(ImuSimulator(off, 1)
	                 .sample(motion, 0, 0)
	                 ->has(mrpt::obs::IMU_ORI_QUAT_W));
}
