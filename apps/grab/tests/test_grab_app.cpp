// bims-grab end to end without hardware: OpenNI2's Dummy device + the
// simulated IMU of the bundled sample replayed in real time.
#include <bims/io/rawlog.h>
#include <bims_test/text.h>
#include <gtest/gtest.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <sys/wait.h>
#include <unistd.h>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

namespace
{
const std::string kGrab = std::string(BIMS_BIN_DIR) + "/bims-grab";
const std::string kIni =
    std::string(BIMS_SOURCE_DIR) + "/apps/grab/examples/dummy_replayed_imu.ini";
const std::string kOut = std::string(BIMS_BINARY_DIR) + "/grab_test";

int run(const std::string& cmd)
{
	const int rc = std::system(cmd.c_str());
	return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

struct Content
{
	size_t scans = 0, imu = 0, backwards = 0;
	bool truncated = false;
	int w = 0, h = 0;
	double t0 = 0, t1 = 0;
};

Content readBack(const std::string& path)
{
	Content c;
	double last = -1e300;
	try
	{
		bims::RawlogReader r(path);
		while (auto o = r.next())
		{
			const double t = mrpt::Clock::toDouble(o->timestamp);
			if (t < last) ++c.backwards;
			last = std::max(last, t);
			if (auto s = std::dynamic_pointer_cast<
			        mrpt::obs::CObservation3DRangeScan>(o))
			{
				if (c.scans == 0) c.t0 = t;
				c.t1 = t;
				++c.scans;
				c.w = static_cast<int>(s->rangeImage.cols());
				c.h = static_cast<int>(s->rangeImage.rows());
				EXPECT_EQ(s->sensorLabel, "RGBD");
				EXPECT_TRUE(s->hasIntensityImage);
				EXPECT_EQ(s->intensityImage.getWidth(), 320u);
				EXPECT_FLOAT_EQ(s->rangeUnits, 0.001f);
				EXPECT_GT(s->cameraParams.fx(), 100);
			}
			else if (auto m =
			             std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(
			                 o))
			{
				++c.imu;
				EXPECT_EQ(m->sensorLabel, "IMU");
				EXPECT_TRUE(m->has(mrpt::obs::IMU_WZ));
			}
		}
	}
	catch (const bims::RawlogError&)
	{
		c.truncated = true;
	}
	return c;
}
}  // namespace

TEST(GrabApp, GrabsNFramesFromTheDummyDeviceWithTheReplayedImu)
{
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const std::string out = kOut + "/dummy.rawlog", log = kOut + "/dummy.log";
	std::remove(out.c_str());
	ASSERT_EQ(run("'" + kGrab + "' '" + kIni + "' -o '" + out +
	              "' --max-frames 20 > '" + log + "' 2>&1"),
	          0)
	    << bims::test::fileText(log);
	const Content c = readBack(out);
	EXPECT_FALSE(c.truncated);
	EXPECT_EQ(c.scans, 20u);
	EXPECT_EQ(c.w, 320);
	EXPECT_EQ(c.h, 240);
	EXPECT_EQ(c.backwards, 0u);  // one clock, written in time order
	// 20 frames at 30 fps ~ 0.63 s; the IMU runs at 100 Hz.
	const double span = c.t1 - c.t0;
	EXPECT_GT(span, 0.4);
	EXPECT_LT(span, 3.0);
	EXPECT_GT(c.imu, static_cast<size_t>(50 * span));
	EXPECT_LT(c.imu, static_cast<size_t>(200 * (span + 1)));
	EXPECT_NE(bims::test::fileText(log).find("20 RGB-D frames"),
	          std::string::npos);
	// Stamps are UNIX time of this host (one clock for all sensors).
	const double now = std::chrono::duration<double>(
	                       std::chrono::system_clock::now().time_since_epoch())
	                       .count();
	EXPECT_NEAR(c.t1, now, 60.0);
}

TEST(GrabApp, ViewerWithoutADisplayFailsBeforeAnySensorOpens)
{
	// it recorded 5 s of IMU and then fell back to grabbing without viewer
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const std::string out = kOut + "/noviewer.rawlog",
	                  log = kOut + "/noviewer.log";
	std::remove(out.c_str());
	const auto t0 = std::chrono::steady_clock::now();
	EXPECT_EQ(
	    run("env -u DISPLAY -u WAYLAND_DISPLAY '" + kGrab + "' '" + kIni +
	        "' -o '" + out + "' --max-frames 20 --viewer > '" + log + "' 2>&1"),
	    1)
	    << bims::test::fileText(log);
	const double s =
	    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
	        .count();
	const std::string text = bims::test::fileText(log);
	EXPECT_NE(text.find("bims-grab: error: --viewer needs a display (DISPLAY "
	                    "is not set)"),
	          std::string::npos)
	    << text;
	// no sensor described, nothing written, no time spent grabbing
	EXPECT_EQ(text.find("RGB-D: "), std::string::npos) << text;
	EXPECT_EQ(text.find("IMU: "), std::string::npos) << text;
	EXPECT_FALSE(std::filesystem::exists(out));
	EXPECT_LT(s, 3.0);
}

TEST(GrabApp, OldSpellingsStillWorkWithANote)
{
	// --frames N and --experiment FILE: now --max-frames N and --config FILE
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const std::string out = kOut + "/old.rawlog", log = kOut + "/old.log";
	EXPECT_EQ(
	    run("'" + kGrab + "' '" + kIni + "' -o '" + out +
	        "' --frames 3 --live-segmentation --experiment '" +
	        BIMS_SOURCE_DIR + "/config/default.ini' -q > '" + log + "' 2>&1"),
	    0)
	    << bims::test::fileText(log);
	const std::string text = bims::test::fileText(log);
	EXPECT_NE(text.find("bims-grab: note: --frames 3 is now --max-frames 3\n"),
	          std::string::npos)
	    << text;
	EXPECT_NE(text.find("bims-grab: note: --experiment"), std::string::npos)
	    << text;
	EXPECT_NE(text.find("parameters from " + std::string(BIMS_SOURCE_DIR) +
	                    "/config/default.ini"),
	          std::string::npos)
	    << text;
	EXPECT_EQ(readBack(out).scans, 3u);
}

TEST(GrabApp, LiveSegmentationWithoutExperimentUsesShareBimsDefaultIni)
{
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const std::string out = kOut + "/seg.rawlog", log = kOut + "/seg.log";
	ASSERT_EQ(run("'" + kGrab + "' '" + kIni + "' -o '" + out +
	              "' --max-frames 3 --live-segmentation > '" + log + "' 2>&1"),
	          0)
	    << bims::test::fileText(log);
	// build/bin/bims-grab -> build/share/bims/default.ini, named
	const std::string msg = bims::test::fileText(log);
	const std::string used = bims::test::restOfLineAfter(
	    msg, "bims-grab: live segmentation: parameters from ");
	ASSERT_FALSE(used.empty()) << msg;
	ASSERT_TRUE(std::filesystem::exists(used)) << msg;
	EXPECT_TRUE(std::filesystem::equivalent(
	    used, std::string(BIMS_BINARY_DIR) + "/share/bims/default.ini"))
	    << used;
}

TEST(GrabApp, NoDeviceIsAClearErrorNotAnAbort)
{
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const std::string ini = kOut + "/nodevice.ini", log = kOut + "/nodev.log";
	std::ofstream(ini) << "[RGBD]\ndriver=OpenNI2\ndevice_uri=" << kOut
	                   << "/no_such_recording.oni\n";
	const int rc = run("'" + kGrab + "' '" + ini + "' -o '" + kOut +
	                   "/nodev.rawlog' > '" + log + "' 2>&1");
	EXPECT_EQ(rc, 1) << bims::test::fileText(log);
	const std::string msg = bims::test::fileText(log);
	EXPECT_NE(msg.find("bims-grab: error: OpenNI2: cannot open device"),
	          std::string::npos)
	    << msg;
}

TEST(GrabApp, BadConfigNamesFileSectionAndKey)
{
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const std::string ini = kOut + "/badkey.ini", log = kOut + "/badkey.log";
	// bims-grab on an .ini of this text: exit 1, its output
	const auto grabWith = [&](const std::string& text)
	{
		std::ofstream(ini) << text;
		EXPECT_EQ(run("'" + kGrab + "' '" + ini + "' -o '" + kOut +
		              "/bad.rawlog' > '" + log + "' 2>&1"),
		          1);
		return bims::test::fileText(log);
	};
	const std::string msg =
	    grabWith("[RGBD]\ndriver=OpenNI2\ndevice_uri=Dummy\nframe_rate=30\n");
	EXPECT_NE(msg.find("frame_rate"), std::string::npos) << msg;
	EXPECT_NE(msg.find("RGBD"), std::string::npos) << msg;
	// a driver that is none: the file, the section and the driver named
	const std::string msg2 = grabWith(
	    "[RGBD]\ndriver=OpenNI2\ndevice_uri=Dummy\n[IMU]\ndriver=NoSuchImu\n");
	EXPECT_NE(msg2.find(ini + ": [IMU] driver=NoSuchImu: not an IMU driver"),
	          std::string::npos)
	    << msg2;
}

TEST(GrabApp, CtrlCStopsCleanlyAndKillLosesAtMostTheLastFrame)
{
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	for (const int sig : {SIGINT, SIGKILL})
	{
		const std::string out = kOut + "/sig" + std::to_string(sig) + ".rawlog";
		std::remove(out.c_str());
		const pid_t pid = fork();
		ASSERT_GE(pid, 0);
		if (pid == 0)
		{
			const std::string log =
			    kOut + "/sig" + std::to_string(sig) + ".log";
			freopen(log.c_str(), "w", stderr);
			execl(kGrab.c_str(), kGrab.c_str(), kIni.c_str(), "-o", out.c_str(),
			      static_cast<char*>(nullptr));
			_exit(127);
		}
		// Wait until about 10 frames are on disk (startup takes ~1 s).
		for (int i = 0; i < 200; ++i)
		{
			std::this_thread::sleep_for(std::chrono::milliseconds(100));
			std::ifstream f(out, std::ios::binary | std::ios::ate);
			if (f && f.tellg() > 10 * 320 * 240 * 5) break;
		}
		kill(pid, sig);
		int status = 0;
		waitpid(pid, &status, 0);
		const Content c = readBack(out);
		EXPECT_GT(c.scans, 5u) << "signal " << sig;
		EXPECT_EQ(c.backwards, 0u);
		if (sig == SIGINT)
		{
			ASSERT_TRUE(WIFEXITED(status));
			EXPECT_EQ(WEXITSTATUS(status), 0);
			EXPECT_FALSE(c.truncated);
		}
		// SIGKILL: everything flushed before the kill reads back (a torn
		// last frame at most shows as a truncated tail).
	}
}

TEST(GrabApp, AFullDiskOrAnUnwritableOutputStopsWithAnErrorNamingTheFile)
{
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	// files limited to 1 MiB (SIGXFSZ ignored: writes fail with EFBIG, as
	// on a full disk): the frames before stay readable
	const std::string out = kOut + "/full.rawlog", log = kOut + "/full.log";
	std::remove(out.c_str());
	EXPECT_EQ(run("bash -c \"ulimit -f 1024; trap '' XFSZ; exec '" + kGrab +
	              "' '" + kIni + "' -o '" + out + "' --max-frames 200\" > '" +
	              log + "' 2>&1"),
	          1)
	    << bims::test::fileText(log);
	EXPECT_NE(bims::test::fileText(log).find("error: grabbing stopped: " + out +
	                                         ": write failed"),
	          std::string::npos)
	    << bims::test::fileText(log);
	const Content c = readBack(out);
	EXPECT_GE(c.scans, 1u);
	EXPECT_LT(c.scans, 200u);
	EXPECT_EQ(c.backwards, 0u);
	// an output folder that is a file
	const std::string file = kOut + "/a_file";
	std::ofstream(file) << "x";
	EXPECT_EQ(run("'" + kGrab + "' '" + kIni + "' -o '" + file +
	              "/x.rawlog' --max-frames 5 > '" + log + "' 2>&1"),
	          1);
	EXPECT_NE(bims::test::fileText(log).find(file + "/x.rawlog: cannot create"),
	          std::string::npos)
	    << bims::test::fileText(log);
}

// Issue 39's reproduction: the rawlog a grab .ini replays its IMU from is
// an input too; -o naming it was written over (16.6 MB became 0.77 MB).
TEST(GrabApp, TheReplayedImuFileOfTheIniIsNeverTheOutput)
{
	const std::string d = kOut + "/replay_alias";
	ASSERT_EQ(run("rm -rf '" + d + "' && mkdir -p '" + d + "'"), 0);
	std::filesystem::copy_file(
	    std::string(BIMS_SOURCE_DIR) + "/rawlogs/pendulum_slow.rawlog",
	    d + "/x.rawlog");
	const auto size = std::filesystem::file_size(d + "/x.rawlog");
	std::ofstream(d + "/d.ini")
	    << "[RGBD]\ndriver=OpenNI2\nsensorLabel=RGBD\ndevice_uri=Dummy\n"
	       "[IMU]\ndriver=RawlogImu\nsensorLabel=IMU\nfile=x.rawlog\n"
	       "source_label=IMU\n";
	const std::string log = d + "/log";
	EXPECT_EQ(run("cd '" + d + "' && '" + kGrab + "' d.ini -o x.rawlog " +
	              "--max-frames 3 > '" + log + "' 2>&1"),
	          2)
	    << bims::test::fileText(log);
	EXPECT_NE(bims::test::fileText(log).find("would overwrite the input"),
	          std::string::npos)
	    << bims::test::fileText(log);
	EXPECT_EQ(std::filesystem::file_size(d + "/x.rawlog"), size);
}
