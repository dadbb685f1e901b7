// bims-viewer under Xvfb: the real wx window with MRPT's GL canvas opens the
// bundled rawlog, steps frames with the pipeline, and the 3D view it drew
// (read back from the canvas) shows the three tier colours.
#include <bims/viewer/panels.h>
#include <bims_test/text.h>
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

namespace
{
const std::string kViewer = std::string(BIMS_BIN_DIR) + "/bims-viewer";
const std::string kRawlog =
    std::string(BIMS_SOURCE_DIR) + "/rawlogs/pendulum_slow.rawlog";
const std::string kOut = std::string(BIMS_BINARY_DIR) + "/gui_test";

std::string slurp(const std::string& p)
{
	std::ifstream f(p);
	std::stringstream s;
	s << f.rdbuf();
	return s.str();
}

int run(const std::string& cmd)
{
	const int rc = std::system(cmd.c_str());
	return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}
}  // namespace

TEST(GuiViewer, XvfbScreenshotShowsTheThreeTierColours)
{
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const std::string shot = kOut + "/viewer_xvfb.png";
	const std::string log = kOut + "/viewer_xvfb.log";
	std::remove(shot.c_str());
	const std::string cmd =
	    std::string(BIMS_XVFB_RUN) +
	    " -a -s '-screen 0 1280x900x24 +extension GLX' '" + kViewer + "' '" +
	    kRawlog + "' --config '" + BIMS_SOURCE_DIR +
	    "/config/default.ini' --max-frames 45 --size 1200x800 --screenshot '" +
	    shot + "' > '" + log + "' 2>&1";
	// (frame 45: with the map-anchored egomotion tier 1 agrees with tier 2
	// almost everywhere by frame 15, and its yellow hides behind the red)
	ASSERT_EQ(run(cmd), 0) << slurp(log);
	const cv::Mat img = cv::imread(shot, cv::IMREAD_COLOR);
	ASSERT_FALSE(img.empty()) << slurp(log);
	EXPECT_GT(img.cols, 300);
	EXPECT_GT(img.rows, 300);
	const auto c = bims::viewer::tierColourFractions(img);
	EXPECT_GT(c.blue, 0.002) << "tier 0 (blue) missing";
	EXPECT_GT(c.yellow, 0.0002) << "tier 1 (yellow) missing";
	EXPECT_GT(c.red, 0.0002) << "tier 2 (red) missing";
	// Non-empty: not a single flat colour.
	cv::Scalar mean, sd;
	cv::meanStdDev(img, mean, sd);
	EXPECT_GT(sd[0] + sd[1] + sd[2], 10.0);
}

TEST(GuiViewer, XScreenshotOfTheWholeWindowShowsTiersAndPanels)
{
	// An X screenshot (ImageMagick's import) of the window as the X server
	// shows it, taken once the viewer has written its own screenshot.
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const std::string own = kOut + "/viewer_own.png";
	const std::string xshot = kOut + "/viewer_x.png";
	const std::string log = kOut + "/viewer_x.log";
	std::remove(own.c_str());
	std::remove(xshot.c_str());
	const std::string cmd =
	    std::string(BIMS_XVFB_RUN) +
	    " -a -s '-screen 0 1200x800x24 +extension GLX' '" + BIMS_SOURCE_DIR +
	    "/apps/viewer/tests/xshot.sh' '" + own + "' '" + xshot + "' '" +
	    kViewer + "' '" + kRawlog + "' --config '" + BIMS_SOURCE_DIR +
	    "/config/default.ini' --max-frames 15 --size 1200x800 > '" + log +
	    "' 2>&1";
	ASSERT_EQ(run(cmd), 0) << slurp(log);
	const cv::Mat img = cv::imread(xshot, cv::IMREAD_COLOR);
	ASSERT_FALSE(img.empty()) << slurp(log);
	const auto c = bims::viewer::tierColourFractions(img);
	EXPECT_GT(c.blue, 0.002) << "tier 0 (blue) missing";
	EXPECT_GT(c.yellow, 0.0001) << "tier 1 (yellow) missing";
	EXPECT_GT(c.red, 0.0002) << "tier 2 (red) missing";
	// The 2D panels on the right: the Diff-labels panel is mostly green.
	const cv::Mat right =
	    img(cv::Rect(img.cols * 2 / 3, 0, img.cols / 3, img.rows));
	cv::Mat green;
	cv::inRange(right, cv::Scalar(0, 120, 0), cv::Scalar(60, 255, 60), green);
	EXPECT_GT(cv::countNonZero(green), 2000);
}

namespace
{
/** Where the image panels are in an X screenshot: the widest run of their
 * background grey (40,40,40) on one row of the right half, and the rows
 * from the first to the last that hold such a run of at least \a minRun. */
struct PanelExtent
{
	int widestRun = 0;
	int rows = 0;
};
PanelExtent panelExtent(const cv::Mat& img, int minRun)
{
	PanelExtent e;
	int first = -1, last = -1;
	for (int y = 0; y < img.rows; ++y)
	{
		int run = 0, widest = 0;
		for (int x = img.cols / 2; x < img.cols; ++x)
		{
			const auto& p = img.at<cv::Vec3b>(y, x);
			run = (p[0] == 40 && p[1] == 40 && p[2] == 40) ? run + 1 : 0;
			widest = std::max(widest, run);
		}
		e.widestRun = std::max(e.widestRun, widest);
		if (widest >= minRun)
		{
			if (first < 0) first = y;
			last = y;
		}
	}
	e.rows = first < 0 ? 0 : last - first + 1;
	return e;
}
}  // namespace

TEST(GuiViewer, PanelsKeepTheirWidthWhilePlaying)
{
	// An X screenshot while the viewer plays (it starts playing at once; at
	// a quarter of real time the 150 frames last 20 s). The six image panels
	// take 2/5 of the 1200 px window, two columns of ~240 px: they collapsed
	// to 50 px once wx moved the sash itself on a resize.
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const std::string xshot = kOut + "/viewer_playing.png";
	const std::string log = kOut + "/viewer_playing.log";
	std::remove(xshot.c_str());
	const std::string cmd =
	    std::string(BIMS_XVFB_RUN) +
	    " -a -s '-screen 0 1200x800x24 +extension GLX' '" + BIMS_SOURCE_DIR +
	    "/apps/viewer/tests/xshot.sh' - '" + xshot + "' '" + kViewer + "' '" +
	    kRawlog + "' --config '" + BIMS_SOURCE_DIR +
	    "/config/default.ini' --speed 0.25 --size 1200x800 > '" + log +
	    "' 2>&1";
	ASSERT_EQ(run(cmd), 0) << slurp(log);
	const cv::Mat img = cv::imread(xshot, cv::IMREAD_COLOR);
	ASSERT_FALSE(img.empty()) << slurp(log);
	const auto e = panelExtent(img, 100);
	EXPECT_GE(e.widestRun, 150) << "image panels collapsed: " << xshot;
	EXPECT_GE(e.rows, img.rows / 2) << "image panels collapsed: " << xshot;
}

TEST(GuiViewer, NoDisplayGivesAClearErrorAndNonZeroExit)
{
	const std::string log = kOut + "/viewer_nodisplay.log";
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const int rc = run("env -u DISPLAY -u WAYLAND_DISPLAY '" + kViewer + "' '" +
	                   kRawlog + "' --max-frames 1 --screenshot '" + kOut +
	                   "/never.png' > '" + log + "' 2>&1");
	EXPECT_NE(rc, 0);
	EXPECT_NE(rc, -1);  // exited, did not crash
	EXPECT_FALSE(slurp(log).empty());
}

TEST(GuiViewer, MissingRawlogIsAnErrorBeforeAnyWindow)
{
	const std::string log = kOut + "/viewer_missing.log";
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const int rc = run("env -u DISPLAY '" + kViewer +
	                   "' /nonexistent/x.rawlog > '" + log + "' 2>&1");
	EXPECT_EQ(rc, 1);
	EXPECT_NE(slurp(log).find("cannot open rawlog '/nonexistent/x.rawlog'"),
	          std::string::npos)
	    << slurp(log);
}

TEST(GuiViewer, WithoutConfigItUsesShareBimsDefaultIniAndSaysWhich)
{
	// The parameters line comes before any window (none opens here).
	const std::string log = kOut + "/viewer_default_ini.log";
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	run("env -u DISPLAY -u WAYLAND_DISPLAY '" + kViewer + "' > '" + log +
	    "' 2>&1");
	const std::string msg = slurp(log);
	const std::string used =
	    bims::test::restOfLineAfter(msg, "bims-viewer: parameters from ");
	ASSERT_FALSE(used.empty()) << msg;
	// build/bin/bims-viewer -> build/share/bims/default.ini
	ASSERT_TRUE(std::filesystem::exists(used)) << msg;
	EXPECT_TRUE(std::filesystem::equivalent(
	    used, std::string(BIMS_BINARY_DIR) + "/share/bims/default.ini"))
	    << used;
	EXPECT_NE(used.find("/share/bims/default.ini"), std::string::npos) << used;
}
