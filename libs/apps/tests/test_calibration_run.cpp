// The calibration programs' runs (calibration_run.h): the gyro/vision
// rotation pairs, bims-calib-imu's .ini, the size of a depth correction and
// both runs on the bundled sample.
#include <bims/apps/app.h>
#include <bims/apps/calibration_run.h>
#include <bims/common/so3.h>
#include <bims/ego/flags.h>
#include <bims_test/sample.h>
#include <bims_test/text.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <sstream>

using namespace bims::apps;

namespace
{
using bims::test::kDefaultConfig;
using bims::test::kSample;
using bims::test::kSampleGt;
using bims::test::kSourceDir;

bims::ego::FrameEgomotion frame(double t, uint32_t flags,
                                const Eigen::Matrix3d& R_CprevC)
{
	bims::ego::FrameEgomotion r;
	r.t = t;
	r.flags = flags;
	mrpt::math::CMatrixDouble33 R;
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) R(i, j) = R_CprevC(i, j);
	r.T_CprevC = mrpt::poses::CPose3D(R, mrpt::math::CVectorFixedDouble<3>());
	return r;
}

Eigen::Matrix3d aboutZ(double rad)
{
	return Eigen::AngleAxisd(rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}
}  // namespace

TEST(RotationPairs, GyroOverEachFrameIntervalBesideTheVisualRotation)
{
	// the IMU clock 0.05 s behind the camera's: frame t is IMU time t + 0.05
	RotationPairCollector c(0.05);
	for (int k = 0; k <= 100; k++)
	{
		bims::sensors::ImuSample s;
		s.t = 0.01 * k;
		s.hasGyro = true;
		s.gyro = Eigen::Vector3d(0, 0, s.t < 0.35 ? 1.0 : 2.0);  // rad/s
		c.addImu(s);
	}
	c.addFrame(frame(0.1, bims::ego::kFlagFirstFrame, aboutZ(0)));
	EXPECT_TRUE(c.pairs().empty());  // no pair for the first frame
	c.addFrame(frame(0.2, 0, aboutZ(0.3)));
	ASSERT_EQ(c.pairs().size(), 1u);
	// IMU 0.15 .. 0.25 at 1 rad/s
	EXPECT_NEAR(bims::angleSO3(c.pairs()[0].R_IprevI), 0.1, 1e-6);
	EXPECT_NEAR(bims::angleSO3(c.pairs()[0].R_CprevC), 0.3, 1e-9);
	// out of order: no pair, and the next interval still starts at 0.2
	c.addFrame(frame(0.15, bims::ego::kFlagOutOfOrder, aboutZ(0)));
	EXPECT_EQ(c.pairs().size(), 1u);
	// a failed frame: no pair, but the interval moves on to 0.25
	c.addFrame(frame(0.25, bims::ego::kFlagTooFewInliers, aboutZ(0)));
	EXPECT_EQ(c.pairs().size(), 1u);
	c.addFrame(frame(0.4, 0, aboutZ(0)));
	ASSERT_EQ(c.pairs().size(), 2u);
	// IMU 0.30 .. 0.45: 0.05 s at 1 rad/s, 0.1 s at 2 rad/s (trapezoid at
	// the step)
	EXPECT_NEAR(bims::angleSO3(c.pairs()[1].R_IprevI), 0.255, 0.006);
}

TEST(ImuCalibrationIni, ReadsBackAsTheEstimateAndOffset)
{
	const Eigen::Matrix3d R =
	    aboutZ(0.25) *
	    Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitX()).toRotationMatrix();
	const std::string ini = imuCalibrationIni(R, 0.0125, "in.rawlog");
	EXPECT_EQ(ini.rfind("# bims-calib-imu estimate from in.rawlog\n"
	                    "[calibration]\n; p_I = R_IC p_C, row major\nR_IC = ",
	                    0),
	          0u)
	    << ini;
	mrpt::config::CConfigFileMemory f(ini);
	std::istringstream v(f.read_string("calibration", "R_IC", ""));
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
		{
			double x = NAN;
			v >> x;
			EXPECT_NEAR(x, R(i, j), 1e-9) << i << j;
		}
	EXPECT_DOUBLE_EQ(f.read_double("calibration", "time_offset_s", NAN),
	                 0.0125);
}

TEST(DepthCalibration, LargestCorrectionIsTheWorstPixel)
{
	Eigen::Matrix3d K;
	K << 100, 0, 160, 0, 100, 120, 0, 0, 1;
	bims::sensors::DepthCorrectionParams p;
	p.enable = true;
	EXPECT_EQ(largestDepthCorrection(p, K, {320, 240}), 0.0);
	p.coefficients[0] = 0.05;  // delta = 0.05 x: worst at the left border
	EXPECT_NEAR(largestDepthCorrection(p, K, {320, 240}), 0.05 * 1.6, 1e-3);
}

TEST(ImuCalibration, EstimatesRICOnTheSampleAndWritesIt)
{
	const std::string d = bims::test::freshTmpDir("bims_test_source", "imu");
	ImuCalibrationOptions o;
	o.config = kDefaultConfig;
	o.rawlog = kSample;
	o.calib = kSampleGt + "calibration.ini";
	o.out = d + "/imu.ini";
	o.min_angle_deg = 0.1;
	o.inlier_deg = 0.05;
	o.progress = false;
	ASSERT_EQ(runImuCalibration(o), 0);
	mrpt::config::CConfigFile est(*o.out), truth(o.calib);
	std::istringstream a(est.read_string("calibration", "R_IC", "")),
	    b(truth.read_string("calibration", "R_IC", ""));
	Eigen::Matrix3d Ra, Rb;
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) a >> Ra(i, j), b >> Rb(i, j);
	EXPECT_LT(bims::angleSO3(Rb.transpose() * Ra) * 180 / M_PI, 10.0);
	// rotations of 50 degrees between frames: none, nothing to estimate from
	o.min_angle_deg = 50;
	o.out = d + "/none.ini";
	EXPECT_THROW(runImuCalibration(o), std::runtime_error);
	EXPECT_FALSE(std::ifstream(*o.out).good());
	o.calib = d + "/missing.ini";
	EXPECT_THROW(runImuCalibration(o), bims::UsageError);
}

TEST(DepthCalibration, FitsAtTheTruePosesAndRefusesTheOdometrysOnTheSample)
{
	const std::string d = bims::test::freshTmpDir("bims_test_source", "depth");
	DepthCalibrationOptions o;
	o.config = kDefaultConfig;
	o.rawlog = kSample;
	o.frames = "0:40";
	o.poses = kSampleGt + "groundtruth.txt";
	o.out = d + "/depth.ini";
	o.progress = false;
	ASSERT_EQ(runDepthCalibration(o), 0);
	EXPECT_NE(bims::test::fileText(o.out).find("[depth_correction]"),
	          std::string::npos);
	// the vision odometry of the 320 x 240 sample is too poor: refused
	o.poses.clear();
	o.out = d + "/refused.ini";
	EXPECT_THROW(runDepthCalibration(o), std::runtime_error);
	EXPECT_FALSE(std::ifstream(o.out).good());
	o.frames = "500:600";
	EXPECT_THROW(runDepthCalibration(o), bims::UsageError);
}
