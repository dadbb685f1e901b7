// The synthetic IMU of an import (bims-import-tum --synth-imu): R_IC and the
// time offset from [calibration], the readings' label and time offset.
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/sim/imu.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

TEST(SynthCalibration, RIcOrItsAnglesAndTheTimeOffsetFromCalibration)
{
	bims::sim::ImuParams imu;
	mrpt::config::CConfigFileMemory none;
	const Eigen::Matrix3d before = imu.R_IC;
	bims::sim::loadSynthCalibration(none, imu);  // no section: unchanged
	EXPECT_TRUE(imu.R_IC.isApprox(before));
	EXPECT_EQ(imu.timeOffsetS, 0.0);

	mrpt::config::CConfigFileMemory ini(std::string(
	    "[calibration]\nR_IC = 0 0 1 1 0 0 0 1 0\ntime_offset_s = 0.01\n"));
	bims::sim::loadSynthCalibration(ini, imu);
	Eigen::Matrix3d M;
	M << 0, 0, 1, 1, 0, 0, 0, 1, 0;
	EXPECT_TRUE(imu.R_IC.isApprox(M));
	EXPECT_DOUBLE_EQ(imu.timeOffsetS, 0.01);

	mrpt::config::CConfigFileMemory angles(
	    std::string("[calibration]\nR_IC_ypr_deg = 90 0 -90\n"));
	bims::sim::loadSynthCalibration(angles, imu);
	bims::sim::ImuParams ypr;
	ypr.setR_IC_ypr(90, 0, -90);
	EXPECT_TRUE(imu.R_IC.isApprox(ypr.R_IC));
	EXPECT_EQ(imu.timeOffsetS, 0.0);

	mrpt::config::CConfigFileMemory bad(
	    std::string("[calibration]\nR_IC = 1 1 1 1 0 0 0 1 0\n"));
	try
	{
		bims::sim::loadSynthCalibration(bad, imu);
		ADD_FAILURE() << "no error for a matrix that is no rotation";
	}
	catch (const std::exception& e)
	{
		EXPECT_NE(std::string(e.what()).find("R_IC: not a rotation matrix"),
		          std::string::npos)
		    << e.what();
	}
}

TEST(SynthCalibration, ImportImuIsLabelledSyntheticAndTakesTheTimeOffset)
{
	bims::Trajectory gt;
	for (int i = 0; i < 10; i++)
		gt.push_back(
		    {5.0 + 0.1 * i, mrpt::poses::CPose3D(0.01 * i, 0, 0, 0, 0, 0)});
	const auto plain = bims::sim::synthesizeImportImu(gt, "XSENS", nullptr, 1);
	ASSERT_FALSE(plain.empty());
	EXPECT_EQ(plain.front()->sensorLabel, "XSENS_SYNTH");
	mrpt::config::CConfigFileMemory ini(
	    std::string("[calibration]\ntime_offset_s = 0.5\n"));
	const auto shifted = bims::sim::synthesizeImportImu(gt, "XSENS", &ini, 1);
	ASSERT_EQ(shifted.size(), plain.size());
	EXPECT_NEAR(mrpt::Clock::toDouble(shifted.front()->timestamp) -
	                mrpt::Clock::toDouble(plain.front()->timestamp),
	            0.5, 1e-6);
}
