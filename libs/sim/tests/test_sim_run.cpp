// bims-sim's run (sim_app.h) called directly: the options' checks, the
// scene run's configuration, the IMU synthesis from a TUM trajectory and
// the summary line; the synthetic IMU of bims-import-tum --synth-imu.
#include <bims/common/app.h>
#include <bims/common/rawlog.h>
#include <bims/common/trajectory.h>
#include <bims/sim/imu.h>
#include <bims/sim/sim_app.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <filesystem>
#include <fstream>

namespace
{
namespace fs = std::filesystem;
const std::string kScene =
    std::string(BIMS_SOURCE_DIR) + "/config/sim/pendulum_slow.ini";

std::string runDir(const std::string& name)
{
	return bims::test::freshTmpDir("bims_test_sim_run", name);
}

/** The UsageError message of runSim(o) ("" when none is thrown). */
std::string usageError(const bims::sim::SimOptions& o)
{
	try
	{
		bims::sim::runSim(o);
	}
	catch (const bims::UsageError& e)
	{
		return e.what();
	}
	return "";
}
}  // namespace

TEST(SimRun, TheOptionsOverrideTheScene)
{
	bims::sim::SimOptions o;
	o.scene = kScene;
	const auto plain = bims::sim::simConfigFor(o);
	EXPECT_EQ(plain.camera.width, 640);
	o.max_frames = 3;
	o.resolution = "320x240";
	o.preview = 2;
	const auto cfg = bims::sim::simConfigFor(o);
	EXPECT_EQ(cfg.seq.frames, 3);
	EXPECT_EQ(cfg.camera.width, 320);
	EXPECT_EQ(cfg.camera.height, 240);
}

TEST(SimRun, BadOptionsAreUsageErrorsBeforeAnyOutput)
{
	const auto d = runDir("usage");
	bims::sim::SimOptions o;
	o.out = d + "/x.rawlog";
	EXPECT_EQ(usageError(o), "missing SCENE.ini (or --imu-from-tum)");
	o.scene = kScene;
	o.imu_from_tum = d + "/gt.txt";
	EXPECT_EQ(usageError(o), "give either SCENE.ini or --imu-from-tum");
	o.imu_from_tum.reset();
	o.config = d + "/imu.ini";
	EXPECT_EQ(usageError(o), "--config only applies to --imu-from-tum");
	o.config.reset();
	o.max_frames = 0;
	EXPECT_EQ(usageError(o), "--max-frames must be >= 1");
	o.max_frames = 3;
	o.preview = 3;
	EXPECT_EQ(usageError(o), "--preview must be a frame index in [0, 2]");
	o.preview.reset();
	o.resolution = "12x3";
	EXPECT_NE(usageError(o).find("12x3"), std::string::npos);
	o.resolution.reset();
	o.out = kScene;
	EXPECT_NE(usageError(o).find("would overwrite the input"),
	          std::string::npos);
	EXPECT_FALSE(fs::exists(d + "/x.rawlog"));
	EXPECT_FALSE(fs::exists(d + "/x_gt"));
}

TEST(SimRun, ImuFromTumWritesTheRawlogAndTheTruth)
{
	const auto d = runDir("imu");
	bims::Trajectory traj;
	for (int i = 0; i < 10; i++)
		traj.push_back({1.0 + 0.1 * i,
		                mrpt::poses::CPose3D(0.01 * i, 0, 0, 0.02 * i, 0, 0)});
	bims::saveTumTrajectory(d + "/gt.txt", traj);
	const std::string line =
	    bims::sim::imuFromTum(d + "/gt.txt", d + "/imu.rawlog", 5, "");
	bims::RawlogReader r(d + "/imu.rawlog");
	size_t n = 0;
	while (r.next()) n++;
	ASSERT_GT(n, 0u);
	EXPECT_EQ(line, "bims-sim: " + std::to_string(n) +
	                    " synthetic IMU samples (label IMU_SYNTH) from 10 "
	                    "poses -> " +
	                    d + "/imu.rawlog, truth in " + d + "/imu_gt/imu.txt\n");
	EXPECT_TRUE(fs::exists(d + "/imu_gt/imu.txt"));
	EXPECT_THROW(bims::sim::imuFromTum(d + "/gt.txt", d + "/b.rawlog", 5,
	                                   d + "/none.ini"),
	             std::runtime_error);
}

TEST(SimRun, TheSummaryLineNamesTheFramesRatesAndTruth)
{
	bims::sim::SimOptions o;
	o.scene = kScene;
	o.resolution = "320x240";
	const auto cfg = bims::sim::simConfigFor(o);
	bims::sim::SimStats st;
	st.frames = 4;
	st.imuSamples = 12;
	st.seconds = 2;
	st.cpuSeconds = 1;
	st.renderSeconds = 0.5;
	st.movingFraction = 0.125;
	st.gtDir = "out_gt";
	EXPECT_EQ(bims::sim::simSummary(st, cfg),
	          "bims-sim: 4 frames 320x240 + 12 IMU samples in 2.00 s wall, "
	          "1.00 s CPU (2.0 frames/s wall, 4.0 frames/s per CPU second, "
	          "render 8.0 frames/s wall); moving pixels 12.5 %; ground truth "
	          "in out_gt\n");
}

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
