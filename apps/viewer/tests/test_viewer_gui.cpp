// bims-viewer under Xvfb: the real wx window with MRPT's GL canvas opens the
// bundled rawlog, steps frames with the pipeline, and the 3D view it drew
// (read back from the canvas) shows the three tier colours.
#include <bims/io/frame_files.h>
#include <bims/io/json.h>
#include <bims/io/rawlog.h>
#include <bims/viewer/panels.h>
#include <bims_test/data.h>
#include <bims_test/text.h>
#include <gtest/gtest.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <sys/wait.h>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <sstream>

namespace
{
const std::string kViewer = std::string(BIMS_BIN_DIR) + "/bims-viewer";
const std::string kRawlog =
    std::string(BIMS_SOURCE_DIR) + "/rawlogs/pendulum_slow.rawlog";
const std::string kOut = std::string(BIMS_BINARY_DIR) + "/gui_test";

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
	    "/config/default.ini' --layers all --max-frames 45 --size 1200x800 "
	    "--screenshot '" +
	    shot + "' > '" + log + "' 2>&1";
	// (frame 45: with the map-anchored egomotion tier 1 agrees with tier 2
	// almost everywhere by frame 15, and its yellow hides behind the red)
	ASSERT_EQ(run(cmd), 0) << bims::test::fileText(log);
	const cv::Mat img = cv::imread(shot, cv::IMREAD_COLOR);
	ASSERT_FALSE(img.empty()) << bims::test::fileText(log);
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
	    "/config/default.ini' --layers all --max-frames 15 --size 1200x800 > "
	    "'" +
	    log + "' 2>&1";
	ASSERT_EQ(run(cmd), 0) << bims::test::fileText(log);
	const cv::Mat img = cv::imread(xshot, cv::IMREAD_COLOR);
	ASSERT_FALSE(img.empty()) << bims::test::fileText(log);
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
	ASSERT_EQ(run(cmd), 0) << bims::test::fileText(log);
	const cv::Mat img = cv::imread(xshot, cv::IMREAD_COLOR);
	ASSERT_FALSE(img.empty()) << bims::test::fileText(log);
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
	EXPECT_NE(bims::test::fileText(log).find("no display"), std::string::npos)
	    << bims::test::fileText(log);
	EXPECT_NE(bims::test::fileText(log).find("xvfb-run"), std::string::npos)
	    << bims::test::fileText(log);
}

TEST(GuiViewer, MissingRawlogIsAnErrorBeforeAnyWindow)
{
	const std::string log = kOut + "/viewer_missing.log";
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	const int rc = run("env -u DISPLAY '" + kViewer +
	                   "' /nonexistent/x.rawlog > '" + log + "' 2>&1");
	EXPECT_EQ(rc, 1);
	EXPECT_NE(bims::test::fileText(log).find(
	              "cannot open rawlog '/nonexistent/x.rawlog'"),
	          std::string::npos)
	    << bims::test::fileText(log);
}

TEST(GuiViewer, WithoutConfigItUsesShareBimsDefaultIniAndSaysWhich)
{
	// The parameters line comes before any window (none opens here).
	const std::string log = kOut + "/viewer_default_ini.log";
	ASSERT_EQ(run("mkdir -p '" + kOut + "'"), 0);
	run("env -u DISPLAY -u WAYLAND_DISPLAY '" + kViewer + "' > '" + log +
	    "' 2>&1");
	const std::string msg = bims::test::fileText(log);
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

namespace
{
/** A fresh folder of this test under the build tree. */
std::string testDir(const std::string& name)
{
	const std::string d = kOut + "/" + name;
	std::filesystem::remove_all(d);
	std::filesystem::create_directories(d);
	return d;
}

/** The simulator's crowded scene at 640x480 (100 frames) in \a dir. */
std::string crowded640(const std::string& dir)
{
	const std::string out = dir + "/crowded.rawlog";
	const std::string cmd = std::string(BIMS_BIN_DIR) + "/bims-sim '" +
	                        BIMS_SOURCE_DIR + "/config/sim/crowded.ini' -o '" +
	                        out + "' --max-frames 100 -q > '" + dir +
	                        "/sim.log' 2>&1";
	EXPECT_EQ(run(cmd), 0) << bims::test::fileText(dir + "/sim.log");
	return out;
}

cv::Rect rectOf(const bims::Json& r)
{
	return cv::Rect(r[0].get<int>(), r[1].get<int>(), r[2].get<int>(),
	                r[3].get<int>());
}

/** Frame N and last M of the counter "N / M" and of the status bar's
 * "frame N/M ...". */
std::pair<std::string, std::string> counterAndStatusFrame(const bims::Json& s)
{
	std::smatch a, b;
	const std::string counter = s["counter"].get<std::string>();
	const std::string status = s["status"].get<std::string>();
	std::regex_search(counter, a, std::regex(R"((\d+) / (\d+))"));
	std::regex_search(status, b, std::regex(R"(^frame (\d+)/(\d+))"));
	return {a.size() == 3 ? a[1].str() + "/" + a[2].str() : "?" + counter,
	        b.size() == 3 ? b[1].str() + "/" + b[2].str() : "?" + status};
}

/** Plays \a args (after the viewer) under Xvfb with one CPU kept busy by
 * another process, and checks two X screenshots taken 3 s apart while it
 * plays: the slider has moved (its state and its pixels), the counter
 * matches the status bar, each 2D panel is at least a fifth of the
 * window's width and shows an image, the 3D view has changed. Returns the
 * second screenshot and its 3D view's rectangle. */
std::pair<cv::Mat, cv::Rect> checkPlayingWindow(const std::string& dir,
                                                const std::string& args,
                                                int panelsWithImages = 5)
{
	const std::string prefix = dir + "/shot";
	const std::string log = dir + "/viewer.log";
	const std::string cmd =
	    "XSHOT_BUSY=1 " + std::string(BIMS_XVFB_RUN) +
	    " -a -s '-screen 0 1280x900x24 +extension GLX' '" + BIMS_SOURCE_DIR +
	    "/apps/viewer/tests/xshot.sh' play2 '" + prefix + "' '" + kViewer +
	    "' " + args + " --size 1280x800 > '" + log + "' 2>&1";
	EXPECT_EQ(run(cmd), 0) << bims::test::fileText(log);
	const cv::Mat a = cv::imread(prefix + ".1.png", cv::IMREAD_COLOR);
	const cv::Mat b = cv::imread(prefix + ".2.png", cv::IMREAD_COLOR);
	if (a.empty() || b.empty())
	{
		ADD_FAILURE() << "no screenshots: " << bims::test::fileText(log);
		return {};
	}
	const auto s1 = bims::Json::parse(bims::test::fileText(prefix + ".1.json"));
	const auto s2 = bims::Json::parse(bims::test::fileText(prefix + ".2.json"));
	// the slider follows playback
	EXPECT_LT(s1["slider"].get<int>(), s2["slider"].get<int>()) << s1 << "\n"
	                                                            << s2;
	EXPECT_EQ(s2["slider"].get<int>(), s2["frame"].get<int>());
	const cv::Rect screen(0, 0, b.cols, b.rows);
	const cv::Rect sl = rectOf(s2["slider_rect"]) & screen;
	EXPECT_GT(cv::norm(a(sl), b(sl), cv::NORM_L1), 0)
	    << "the slider did not move on screen";
	// the frame counter matches the status bar
	for (const auto* s : {&s1, &s2})
	{
		const auto [counter, status] = counterAndStatusFrame(*s);
		EXPECT_EQ(counter, status) << *s;
	}
	// each 2D panel at least a fifth of the window's width, with an image
	const int W = s2["window"][2].get<int>();
	int k = 0;
	for (const auto& r : s2["panels"])
	{
		const cv::Rect pr = rectOf(r);
		EXPECT_GE(pr.width * 5, W) << "panel " << k << " " << r;
		// below the caption: an image (a panel without one says why, in
		// a line of text on grey)
		const cv::Rect body(pr.x, pr.y + 20, pr.width, pr.height - 20);
		cv::Scalar mean, sd;
		cv::meanStdDev(b(body & cv::Rect(0, 0, b.cols, b.rows)), mean, sd);
		if (k < panelsWithImages)
		{
			EXPECT_GT(sd[0] + sd[1] + sd[2], 30.0) << "panel " << k << " blank";
		}
		++k;
	}
	EXPECT_EQ(k, 5);
	// the 3D view differs between the two
	const cv::Rect v3 = rectOf(s2["view3d"]) & screen;
	EXPECT_GE(v3.width * 3, W);
	EXPECT_GT(cv::norm(a(v3), b(v3), cv::NORM_L1) / v3.area(), 1.0)
	    << "the 3D view did not change";
	return {b, v3};
}
}  // namespace

// The 640x480 simulation played with the CPU kept busy: the pipeline runs
// off the GUI thread, the window keeps drawing the newest frame.
TEST(GuiViewer, PlayingVgaUnderLoadKeepsSliderCounterPanelsAndViewLive)
{
	const std::string dir = testDir("playing_vga");
	const std::string in = crowded640(dir);
	const auto [img, v3] =
	    checkPlayingWindow(dir, "'" + in + "' --config '" + BIMS_SOURCE_DIR +
	                                "/config/default.ini' --speed 0.5");
	if (img.empty()) return;
	// what moves is shown: red in the 3D view (moving points and voxels)
	const auto c = bims::viewer::tierColourFractions(img(v3));
	EXPECT_GT(c.red, 0.002);
}

// The same for a bims-run output folder shown with --results, which also
// says nothing of parameters it does not use.
TEST(GuiViewer, ResultsModePlaysWithTheSameLayoutAndShowsWhatMoves)
{
	const std::string dir = testDir("results_vga");
	const std::string in = crowded640(dir);
	ASSERT_EQ(run(std::string(BIMS_BIN_DIR) + "/bims-run '" + BIMS_SOURCE_DIR +
	              "/config/default.ini' '" + in + "' -o '" + dir +
	              "/out' -q > '" + dir + "/run.log' 2>&1"),
	          0)
	    << bims::test::fileText(dir + "/run.log");
	const auto [img, v3] = checkPlayingWindow(
	    dir, "'" + in + "' --results '" + dir + "/out' --speed 0.5",
	    2);  // RGB + mask, depth; no pipeline: no flow
	EXPECT_EQ(bims::test::fileText(dir + "/viewer.log").find("parameters from"),
	          std::string::npos)
	    << bims::test::fileText(dir + "/viewer.log");
	if (img.empty()) return;
	// the moving points of the cloud, red from the results' masks
	const auto c = bims::viewer::tierColourFractions(img(v3));
	EXPECT_GT(c.red, 0.002);
}

// The Bonn slice (640x480 real crowd) where ../shared/data is at hand.
TEST(GuiViewer, PlayingTheBonnSliceKeepsTheWindowLive)
{
	if (!std::filesystem::exists(bims::test::kBonnCrowd + "/depth.txt"))
		GTEST_SKIP() << "no Bonn sample at " << bims::test::kBonnCrowd;
	const std::string dir = testDir("playing_bonn");
	ASSERT_EQ(
	    run(std::string(BIMS_BIN_DIR) + "/bims-import-tum '" +
	        bims::test::kBonnCrowd + "' -o '" + dir + "/bonn.rawlog' -c '" +
	        BIMS_SOURCE_DIR + "/config/bonn.ini' --max-frames 120 -q > '" +
	        dir + "/import.log' 2>&1"),
	    0)
	    << bims::test::fileText(dir + "/import.log");
	checkPlayingWindow(dir, "'" + dir + "/bonn.rawlog' --config '" +
	                            BIMS_SOURCE_DIR + "/config/bonn.ini'");
}

// A phone's LiDAR capture (256x192, depth + IMU, no colour) where
// ../shared/data is at hand: the same layout at a phone's image size; the
// mask is drawn over the depth in grey, the flow panels say why they are
// empty (no colour: the flow tier is off).
TEST(GuiViewer, PlayingAPhoneCaptureKeepsTheLayoutAtItsImageSize)
{
	if (!std::filesystem::exists(bims::test::kStrayEarly + "/imu.csv"))
		GTEST_SKIP() << "no Stray capture at " << bims::test::kStrayEarly;
	const std::string dir = testDir("playing_stray");
	ASSERT_EQ(run(std::string(BIMS_BIN_DIR) + "/bims-import-stray '" +
	              bims::test::kStrayEarly + "' -o '" + dir +
	              "/stray.rawlog' -c '" + BIMS_SOURCE_DIR +
	              "/config/stray.ini' -q > '" + dir + "/import.log' 2>&1"),
	          0)
	    << bims::test::fileText(dir + "/import.log");
	checkPlayingWindow(dir,
	                   "'" + dir + "/stray.rawlog' --config '" +
	                       BIMS_SOURCE_DIR + "/config/stray.ini'",
	                   2);  // mask over grey depth, depth; no flow
}

namespace
{
/** The camera model of \a c scaled by 2 and cropped by \a top rows. */
mrpt::img::TCamera scaledAndCropped(mrpt::img::TCamera c, int top)
{
	c.ncols *= 2;
	c.nrows = c.nrows * 2 - 2 * top;
	c.fx(c.fx() * 2);
	c.fy(c.fy() * 2);
	c.cx(c.cx() * 2);
	c.cy(c.cy() * 2 - top);
	return c;
}

/** The first \a frames scans of the 640x480 \a in as 1280x720 (each image
 * doubled, 120 rows cut off top and bottom, the intrinsics alike), with the
 * IMU samples between them. */
void upscaleTo720p(const std::string& in, const std::string& out, int frames)
{
	bims::RawlogReader r(in);
	bims::RawlogWriter w(out, 1);
	int scans = 0;
	while (auto o = r.next())
	{
		auto* s = dynamic_cast<mrpt::obs::CObservation3DRangeScan*>(o.get());
		if (s)
		{
			if (scans++ == frames) break;
			const auto& ri = s->rangeImage;
			cv::Mat d(static_cast<int>(ri.rows()), static_cast<int>(ri.cols()),
			          CV_16UC1);
			for (int y = 0; y < d.rows; ++y)
				for (int x = 0; x < d.cols; ++x)
					d.at<uint16_t>(y, x) = ri(y, x);
			cv::resize(d, d, cv::Size(), 2, 2, cv::INTER_NEAREST);
			d = d(cv::Rect(0, 120, 1280, 720)).clone();
			s->rangeImage.resize(d.rows, d.cols);
			for (int y = 0; y < d.rows; ++y)
				for (int x = 0; x < d.cols; ++x)
					s->rangeImage(y, x) = d.at<uint16_t>(y, x);
			cv::Mat img =
			    s->intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY);
			cv::resize(img, img, cv::Size(), 2, 2, cv::INTER_LINEAR);
			s->intensityImage = mrpt::img::CImage(
			    img(cv::Rect(0, 120, 1280, 720)).clone(), mrpt::img::DEEP_COPY);
			s->cameraParams = scaledAndCropped(s->cameraParams, 120);
			s->cameraParamsIntensity =
			    scaledAndCropped(s->cameraParamsIntensity, 120);
		}
		w.write(*o);
	}
}
}  // namespace

// A 1280x720 recording (the simulation doubled and cut to 16:9): the panels
// keep its aspect ratio, the window stays live.
TEST(GuiViewer, PlayingA720pRecordingKeepsTheLayoutAtItsImageSize)
{
	const std::string dir = testDir("playing_720p");
	const std::string in = dir + "/crowded720.rawlog";
	upscaleTo720p(crowded640(dir), in, 80);
	const auto [img, v3] =
	    checkPlayingWindow(dir, "'" + in + "' --config '" + BIMS_SOURCE_DIR +
	                                "/config/default.ini' --speed 0.25");
	if (img.empty()) return;
	// The depth panel (jet colours, no flat row): the rows that show the
	// image, below the caption, are 9/16 of its width; the rest of the cell
	// is the flat background.
	const auto s =
	    bims::Json::parse(bims::test::fileText(dir + "/shot.2.json"));
	const cv::Rect pr = rectOf(s["panels"][1]);
	const cv::Rect body = cv::Rect(pr.x, pr.y + 20, pr.width, pr.height - 20) &
	                      cv::Rect(0, 0, img.cols, img.rows);
	int imageRows = 0;
	for (int y = body.y; y < body.y + body.height; ++y)
	{
		cv::Scalar mean, sd;
		cv::meanStdDev(img(cv::Rect(body.x + 2, y, body.width - 4, 1)), mean,
		               sd);
		imageRows += sd[0] + sd[1] + sd[2] > 10;
	}
	EXPECT_NEAR(imageRows, body.width * 9.0 / 16.0, 4) << pr;
	EXPECT_LT(imageRows, body.height - 10) << "no band: 4:3, not 16:9";
}

// --paused shows the first frame (not "-1 / N" and empty panels).
TEST(GuiViewer, PausedShowsTheFirstFrame)
{
	const std::string dir = testDir("paused");
	const std::string own = dir + "/own.png";
	const std::string state = dir + "/state.json";
	const std::string log = dir + "/viewer.log";
	const std::string cmd =
	    std::string(BIMS_XVFB_RUN) +
	    " -a -s '-screen 0 1200x800x24 +extension GLX' '" + BIMS_SOURCE_DIR +
	    "/apps/viewer/tests/xshot.sh' - '" + dir + "/x.png' '" + kViewer +
	    "' '" + kRawlog + "' --paused --size 1200x800 --state-file '" + state +
	    "' > '" + log + "' 2>&1";
	ASSERT_EQ(run(cmd), 0) << bims::test::fileText(log);
	const auto s = bims::Json::parse(bims::test::fileText(state));
	EXPECT_EQ(s["frame"].get<int>(), 0) << s;
	EXPECT_EQ(s["counter"].get<std::string>(), "0 / 149") << s;
	EXPECT_FALSE(s["playing"].get<bool>()) << s;
	const cv::Mat img = cv::imread(dir + "/x.png", cv::IMREAD_COLOR);
	ASSERT_FALSE(img.empty());
	const cv::Rect panel = rectOf(s["panels"][0]);
	const cv::Rect rgb =
	    cv::Rect(panel.x, panel.y + 20, panel.width, panel.height - 20) &
	    cv::Rect(0, 0, img.cols, img.rows);
	ASSERT_GT(rgb.area(), 1000) << s;
	cv::Scalar mean, sd;
	cv::meanStdDev(img(rgb), mean, sd);
	EXPECT_GT(sd[0] + sd[1] + sd[2], 20.0) << "the RGB panel is blank";
}

// A PNG sequence holds every frame played, in order, none skipped (it
// plays every frame: each is drawn and written before the next runs).
TEST(GuiViewer, PngSequenceWritesEveryFrameInOrder)
{
	const std::string dir = testDir("png_sequence");
	const std::string log = dir + "/viewer.log";
	const std::string cmd =
	    "XSHOT_BUSY=1 " + std::string(BIMS_XVFB_RUN) +
	    " -a -s '-screen 0 1200x800x24 +extension GLX' '" + BIMS_SOURCE_DIR +
	    "/apps/viewer/tests/xshot.sh' - '" + dir + "/x.png' '" + kViewer +
	    "' '" + kRawlog + "' --size 900x600 --png-sequence '" + dir +
	    "/seq' > '" + log + "' 2>&1";
	ASSERT_EQ(run(cmd), 0) << bims::test::fileText(log);
	std::vector<std::string> names;
	for (const auto& e : std::filesystem::directory_iterator(dir + "/seq"))
		if (e.path().extension() == ".png")  // not a .partial cut by the kill
			names.push_back(e.path().filename().string());
	std::sort(names.begin(), names.end());
	ASSERT_GE(names.size(), 5u) << bims::test::fileText(log);
	for (size_t i = 0; i < names.size(); ++i)
		EXPECT_EQ(names[i], bims::frameFileName(i)) << "a frame was skipped";
	const cv::Mat last = cv::imread(dir + "/seq/" + names.back());
	EXPECT_NEAR(last.cols, 450, 30);  // the 3D view: half the window
}
