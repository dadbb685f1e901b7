// AttitudeFilter: convergence from a wrong state, gating of magnetic
// disturbances and linear accelerations, interpolation, bad input.
#include <bims/common/so3.h>
#include <bims/ego/attitude_filter.h>
#include <bims/ego/flags.h>
#include <gtest/gtest.h>

#include <random>

#include "synth_scene.h"

using namespace bims;  // so3.h
using namespace bims::ego;
using bims::ego::test::Motion;

namespace
{
double errDeg(const Eigen::Quaterniond& a, const Eigen::Matrix3d& R)
{
	return angleSO3(a.toRotationMatrix().transpose() * R) * 180 / M_PI;
}

// Slow rotation, noisy gyro with a bias, 100 Hz.
struct Stream
{
	Motion m;
	Eigen::Vector3d bias{0.01, -0.02, 0.015};
	std::mt19937 rng{42};
	std::normal_distribution<double> n{0.0, 1.0};
	ImuSample at(double t)
	{
		ImuSample s = test::imuAt(m, Eigen::Matrix3d::Identity(), t);
		for (int k = 0; k < 3; k++)
		{
			s.gyro[k] += bias[k] + 0.003 * n(rng);
			s.acc[k] += 0.05 * n(rng);
			s.mag[k] += 0.003 * n(rng);
		}
		return s;
	}
	Eigen::Matrix3d R_WI(double t) const { return m.R(t); }
};
}  // namespace

TEST(AttitudeFilter, InitialisesFromGravityAndNorth)
{
	Stream st;
	AttitudeFilter f;
	f.add(st.at(0));
	ASSERT_TRUE(f.initialized());
	EXPECT_LT(errDeg(f.q_WI(), st.R_WI(0)), 2.0);
}

TEST(AttitudeFilter, ConvergesFromWrongInitialState)
{
	Stream st;
	st.m.w_C = {0.05, 0.2, -0.1};
	AttitudeFilter f;
	const Eigen::Matrix3d wrong =
	    st.R_WI(0) * expSO3(Eigen::Vector3d(1.0, -1.5, 0.8));  // ~105 deg off
	f.setState(Eigen::Quaterniond(wrong), 0);
	EXPECT_GT(errDeg(f.q_WI(), st.R_WI(0)), 90);
	for (int i = 1; i <= 6000; i++) f.add(st.at(i * 0.01));
	EXPECT_LT(errDeg(f.q_WI(), st.R_WI(60)), 1.0);
	EXPECT_LT((f.gyroBias() - st.bias).norm(), 0.005);
}

TEST(AttitudeFilter, RejectsMagneticDisturbance)
{
	// Still sensor; from t = 10 s to 20 s a ferrous object adds a field that
	// changes norm and dip. Gated filter keeps the heading; ungated does not.
	const auto run = [](double normGate)
	{
		Stream st;
		st.m.w_C.setZero();
		st.bias.setZero();
		AttitudeParams p;
		p.mag_norm_gate = normGate;
		p.mag_dip_gate_deg = normGate > 1 ? 180 : 4;
		p.mag_heading_gate_deg = normGate > 1 ? 180 : 3;
		AttitudeFilter f(p);
		double worst = 0;
		size_t gated = 0;
		for (int i = 0; i <= 2500; i++)
		{
			const double t = i * 0.01;
			ImuSample s = st.at(t);
			if (t >= 10 && t < 20)  // +0.3 towards west, in {W}
				s.mag +=
				    st.R_WI(t).transpose() * Eigen::Vector3d(0.0, 0.3, 0.05);
			if (f.add(s) & kFlagMagGated) ++gated;
			if (t > 5) worst = std::max(worst, errDeg(f.q_WI(), st.R_WI(t)));
		}
		return std::make_pair(worst, gated);
	};
	const auto [gatedErr, nGated] = run(0.08);
	const auto [openErr, nOpen] = run(1e3);
	EXPECT_LT(gatedErr, 1.0);
	EXPECT_GT(nGated, 990u);
	EXPECT_EQ(nOpen, 0u);
	EXPECT_GT(openErr, 10.0);  // the disturbance really matters
}

TEST(AttitudeFilter, GatesAccelerometerUnderLinearAcceleration)
{
	Stream st;
	st.m.w_C.setZero();
	st.bias.setZero();
	AttitudeFilter f;
	double worst = 0;
	for (int i = 0; i <= 1500; i++)
	{
		const double t = i * 0.01;
		ImuSample s = st.at(t);
		// 4 m/s^2 forward acceleration for 2.5 s (norm only 0.8 m/s^2 off g,
		// so the innovation-angle gate must catch it): would tilt an ungated
		// filter by atan(4/9.8) = 22 deg.
		if (t >= 5 && t < 7.5)
			s.acc += st.R_WI(t).transpose() * Eigen::Vector3d(4, 0, 0);
		f.add(s);
		if (t > 2) worst = std::max(worst, errDeg(f.q_WI(), st.R_WI(t)));
	}
	EXPECT_GT(f.stats().accelGated, 240u);
	EXPECT_LT(worst, 1.0);
}

TEST(AttitudeFilter, InterpolatesBetweenSamples)
{
	Stream st;
	st.bias.setZero();
	AttitudeFilter f;
	for (int i = 0; i <= 1000; i++) f.add(st.at(i * 0.01));
	for (double t : {9.003, 9.5071, 9.9999})
	{
		const auto q = f.attitudeAt(t);
		ASSERT_TRUE(q.has_value());
		EXPECT_LT(errDeg(*q, st.R_WI(t)), 0.5) << t;
	}
	uint32_t flags = 0;
	EXPECT_TRUE(
	    f.attitudeAt(10.02, &flags).has_value());  // short extrapolation
	EXPECT_FALSE(f.attitudeAt(11.0, &flags).has_value());  // too far
	EXPECT_TRUE(flags & kFlagImuMissing);
}

TEST(AttitudeFilter, FlagsOutOfOrderAndGaps)
{
	Stream st;
	AttitudeFilter f;
	f.add(st.at(0));
	EXPECT_EQ(f.add(st.at(0.01)), 0u);
	EXPECT_TRUE(f.add(st.at(0.005)) & kFlagOutOfOrder);
	EXPECT_TRUE(f.add(st.at(0.01)) & kFlagOutOfOrder);
	EXPECT_TRUE(f.add(st.at(1.0)) & kFlagImuGap);
	uint32_t flags = 0;
	EXPECT_TRUE(f.attitudeAt(0.5, &flags).has_value());
	EXPECT_TRUE(flags & kFlagImuGap);
	EXPECT_EQ(f.stats().outOfOrder, 2u);
}

TEST(AttitudeFilter, UsesSensorOrientationWhenConfigured)
{
	AttitudeParams p;
	p.use_sensor_orientation = true;
	AttitudeFilter f(p);
	const Eigen::Quaterniond q(expSO3(Eigen::Vector3d(0.3, -0.2, 1.0)));
	ImuSample s;
	s.t = 1;
	s.q_WI = q;
	f.add(s);
	ASSERT_TRUE(f.initialized());
	EXPECT_LT(errDeg(f.q_WI(), q.toRotationMatrix()), 1e-9);
}

TEST(AttitudeFilter, ConvertsMrptObservation)
{
	mrpt::obs::CObservationIMU o;
	o.timestamp = mrpt::Clock::fromDouble(12.5);
	o.set(mrpt::obs::IMU_WX, 0.1);
	o.set(mrpt::obs::IMU_WY, 0.2);
	o.set(mrpt::obs::IMU_WZ, 0.3);
	o.set(mrpt::obs::IMU_X_ACC, 0);
	o.set(mrpt::obs::IMU_Y_ACC, 0);
	o.set(mrpt::obs::IMU_Z_ACC, 9.8);
	const ImuSample s = imuSampleFrom(o);
	EXPECT_NEAR(s.t, 12.5, 1e-6);
	EXPECT_TRUE(s.hasGyro && s.hasAcc);
	EXPECT_FALSE(s.hasMag);
	EXPECT_FALSE(s.q_WI.has_value());
	EXPECT_DOUBLE_EQ(s.gyro.z(), 0.3);
}

// A phone's IMU (no magnetometer): tilt from gravity, heading from the gyro.
// No sample is flagged (nothing missing that was never there), the tilt
// holds, and the heading drifts no faster than the gyro's bias allows.
TEST(AttitudeFilter, WithoutAMagnetometerTiltHoldsAndNothingIsFlagged)
{
	Stream st;
	st.m.w_C = {0.05, 0.2, -0.1};
	AttitudeParams p;
	p.use_magnetometer = false;
	AttitudeFilter f(p);
	double worstTilt = 0;
	Eigen::Matrix3d D0 = Eigen::Matrix3d::Zero();
	for (int i = 0; i <= 6000; i++)
	{
		ImuSample s = st.at(i * 0.01);
		s.hasMag = false;
		s.mag.setZero();
		const uint32_t flags = f.add(s);
		ASSERT_EQ(flags, 0u) << "sample " << i << ": " << flagsToString(flags);
		if (i * 0.01 < p.init_time_s) continue;
		if (D0.isZero())  // the start's heading is arbitrary without north
			D0 = f.q_WI().toRotationMatrix() * st.R_WI(i * 0.01).transpose();
		const Eigen::Vector3d upEst =
		    f.q_WI().toRotationMatrix().transpose() * Eigen::Vector3d::UnitZ();
		const Eigen::Vector3d upTrue =
		    st.R_WI(i * 0.01).transpose() * Eigen::Vector3d::UnitZ();
		worstTilt =
		    std::max(worstTilt,
		             std::acos(std::min(1.0, upEst.dot(upTrue))) * 180 / M_PI);
	}
	ASSERT_TRUE(f.initialized());
	EXPECT_LT(worstTilt, 1.0);
	EXPECT_EQ(f.stats().magGated, 0u);
	// the heading error since the start: bounded by the whole bias
	// integrated (its vertical part is unobserved without a magnetometer)
	const Eigen::Matrix3d D =
	    f.q_WI().toRotationMatrix() * st.R_WI(60).transpose();
	const double err = angleSO3(D * D0.transpose()) * 180 / M_PI;
	std::printf("heading error after 59 s: %.2f deg\n", err);
	EXPECT_LT(err, st.bias.norm() * 59 * 180 / M_PI);
}
