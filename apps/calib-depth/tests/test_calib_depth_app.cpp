// bims-calib-depth end to end on the bundled sample (simulated: no depth
// distortion to find).
#include <bims/ego/depth_correction.h>

#include <mrpt/config/CConfigFile.h>

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <utility>
#include "bims_test/text.h"

namespace
{
const std::string kApp = std::string(BIMS_BIN_DIR) + "/bims-calib-depth";
const std::string kSrc = BIMS_SOURCE_DIR;
const std::string kOut = std::string(BIMS_BINARY_DIR) + "/calib_depth_test";

int run(const std::string& args, const std::string& log)
{
	const int rc =
	    std::system((kApp + " " + args + " > '" + log + "' 2>&1").c_str());
	return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

const std::string kSample = "'" + kSrc + "/config/default.ini' '" + kSrc +
                            "/rawlogs/pendulum_slow.rawlog' ";

/** The output kOut/NAME.ini (removed first) and log kOut/NAME.log. */
std::pair<std::string, std::string> freshOutput(const std::string& name)
{
	EXPECT_EQ(std::system(("mkdir -p '" + kOut + "'").c_str()), 0);
	const std::string out = kOut + "/" + name + ".ini";
	std::remove(out.c_str());
	return {out, kOut + "/" + name + ".log"};
}

}  // namespace

TEST(CalibDepthApp, AnUndistortedSensorGetsAlmostNoCorrection)
{
	const auto [out, log] = freshOutput("sample");
	ASSERT_EQ(run(kSample + "--frames 0:40 --poses '" + kSrc +
	                  "/rawlogs/pendulum_slow_gt/groundtruth.txt' -o '" + out +
	                  "' -q",
	              log),
	          0)
	    << bims::test::fileText(log);
	mrpt::config::CConfigFile f(out);
	bims::sensors::DepthCorrectionParams p;
	p.loadFromConfigFile(f);
	EXPECT_TRUE(p.enable);
	// at the borders and corners of the 320 x 240 sample (fx 270)
	for (const auto& [x, y] : {std::pair{-0.59, 0.0},
	                           {0.59, 0.0},
	                           {0.0, -0.44},
	                           {0.0, 0.44},
	                           {-0.59, -0.44},
	                           {0.59, 0.44}})
	{
		EXPECT_LT(std::abs(bims::sensors::depthCorrectionDelta(p, x, y)), 0.025)
		    << x << " " << y;
	}
}

TEST(CalibDepthApp, PosesThatDoNotFitAreRefusedNotWritten)
{
	const auto [out, log] = freshOutput("refused");
	// the 320 x 240 sample's frame-to-frame vision odometry is too poor
	// (0.34 deg per frame) for a fit: refused with a reason
	EXPECT_EQ(run(kSample + "--frames 0:40 -o '" + out + "' -q", log), 1);
	EXPECT_NE(bims::test::fileText(log).find("do not fit a static scene"),
	          std::string::npos)
	    << bims::test::fileText(log);
	EXPECT_FALSE(std::ifstream(out).good());
	// bad arguments are usage errors
	EXPECT_EQ(run(kSample + "--frames 9:2 -o '" + out + "'", log), 2);
	EXPECT_EQ(run("'" + kSrc + "/config/default.ini' /nonexistent.rawlog -o '" +
	                  out + "'",
	              log),
	          1);
	EXPECT_NE(bims::test::fileText(log).find("/nonexistent.rawlog"),
	          std::string::npos);
}
