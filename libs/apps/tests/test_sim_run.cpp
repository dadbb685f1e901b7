// bims-sim's run (sim_app.h) called directly: the options' checks, the
// scene run's configuration, the IMU synthesis from a TUM trajectory and
// the summary line; the synthetic IMU of bims-import-tum --synth-imu.
#include <bims/apps/app.h>
#include <bims/apps/sim_run.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/sim/imu.h>
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
std::string usageError(const bims::apps::SimOptions& o)
{
	try
	{
		bims::apps::runSim(o);
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
	bims::apps::SimOptions o;
	o.scene = kScene;
	const auto plain = bims::apps::simConfigFor(o);
	EXPECT_EQ(plain.camera.width, 640);
	o.max_frames = 3;
	o.resolution = "320x240";
	o.preview = 2;
	const auto cfg = bims::apps::simConfigFor(o);
	EXPECT_EQ(cfg.seq.frames, 3);
	EXPECT_EQ(cfg.camera.width, 320);
	EXPECT_EQ(cfg.camera.height, 240);
}

TEST(SimRun, BadOptionsAreUsageErrorsBeforeAnyOutput)
{
	const auto d = runDir("usage");
	bims::apps::SimOptions o;
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
	    bims::apps::imuFromTum(d + "/gt.txt", d + "/imu.rawlog", 5, "");
	bims::RawlogReader r(d + "/imu.rawlog");
	size_t n = 0;
	while (r.next()) n++;
	ASSERT_GT(n, 0u);
	EXPECT_EQ(line, "bims-sim: " + std::to_string(n) +
	                    " synthetic IMU samples (label IMU_SYNTH) from 10 "
	                    "poses -> " +
	                    d + "/imu.rawlog, truth in " + d + "/imu_gt/imu.txt\n");
	EXPECT_TRUE(fs::exists(d + "/imu_gt/imu.txt"));
	EXPECT_THROW(bims::apps::imuFromTum(d + "/gt.txt", d + "/b.rawlog", 5,
	                                    d + "/none.ini"),
	             std::runtime_error);
}

TEST(SimRun, TheSummaryLineNamesTheFramesRatesAndTruth)
{
	bims::apps::SimOptions o;
	o.scene = kScene;
	o.resolution = "320x240";
	const auto cfg = bims::apps::simConfigFor(o);
	bims::sim::SimStats st;
	st.frames = 4;
	st.imuSamples = 12;
	st.seconds = 2;
	st.cpuSeconds = 1;
	st.renderSeconds = 0.5;
	st.movingFraction = 0.125;
	st.gtDir = "out_gt";
	EXPECT_EQ(bims::apps::simSummary(st, cfg),
	          "bims-sim: 4 frames 320x240 + 12 IMU samples in 2.00 s wall, "
	          "1.00 s CPU (2.0 frames/s wall, 4.0 frames/s per CPU second, "
	          "render 8.0 frames/s wall); moving pixels 12.5 %; ground truth "
	          "in out_gt\n");
}
