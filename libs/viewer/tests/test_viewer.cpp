// The viewer's controller, without any GUI: replay order, timeline, play
// clock, pipeline while replaying, panels, results folders, and an offscreen
// render of the 3D view in which the three tier colours must appear.
#include <bims/io/output_paths.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/pipeline/run.h>
#include <bims/viewer/controller.h>
#include <bims/viewer/panels.h>
#include <bims/viewer/replay_worker.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <thread>

#include <mrpt/system/filesystem.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>

using namespace bims;
using namespace bims::viewer;

namespace
{
const std::string kRawlog =
    std::string(BIMS_SOURCE_DIR) + "/rawlogs/pendulum_slow.rawlog";
const std::string kConfig =
    std::string(BIMS_SOURCE_DIR) + "/config/default.ini";

ViewerOptions sampleOptions()
{
	ViewerOptions o;
	o.rawlog = kRawlog;
	o.configPath = kConfig;
	return o;
}
}  // namespace

TEST(ReplaySource, IndexesScansAndDeliversEveryImuSampleBeforeItsFrame)
{
	source::FrameOrderParams p;
	p.sensors.rgbd_label = "RGBD";
	p.sensors.imu_label = "IMU";
	p.imuWaitS = 0.1;
	ReplaySource src(kRawlog, p);
	ASSERT_EQ(src.frameCount(), 150u);
	EXPECT_EQ(src.imuCount(), 499u);
	EXPECT_NEAR(src.frameTimes()[1] - src.frameTimes()[0], 1.0 / 30, 1e-3);

	size_t n = 0, imu = 0;
	while (auto f = src.next())
	{
		EXPECT_EQ(f->index, n);
		EXPECT_NEAR(f->t, src.frameTimes()[n], 1e-9);
		imu += f->imu.size();
		// IMU samples come before (or up to imuWaitS after) their frame.
		for (const auto& m : f->imu)
			EXPECT_LE(mrpt::Clock::toDouble(m->timestamp), f->t + 0.1 + 1e-6);
		++n;
	}
	EXPECT_EQ(n, 150u);
	// Every sample up to the last frame (those after it feed no frame).
	EXPECT_GE(imu, 496u);
	EXPECT_LE(imu, 499u);

	src.rewind();
	auto f0 = src.next();
	ASSERT_TRUE(f0.has_value());
	EXPECT_EQ(f0->index, 0u);
}

TEST(ReplaySource, RejectsMissingFileAndUnknownLabel)
{
	EXPECT_THROW(ReplaySource("/nonexistent/x.rawlog", {}), std::exception);
	source::FrameOrderParams p;
	p.sensors.rgbd_label = "KINECT_NOPE";
	try
	{
		ReplaySource s(kRawlog, p);
		FAIL() << "no throw";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("KINECT_NOPE"), std::string::npos);
	}
}

TEST(ReplayController, StepsRunThePipelineAndSeekBackRestarts)
{
	ReplayController c(sampleOptions());
	EXPECT_EQ(c.frameCount(), 150u);
	EXPECT_EQ(c.currentFrame(), -1);
	EXPECT_EQ(c.result(), nullptr);
	for (int i = 0; i < 5; ++i) ASSERT_TRUE(c.step());
	EXPECT_EQ(c.currentFrame(), 4);
	ASSERT_NE(c.result(), nullptr);
	EXPECT_EQ(c.result()->index, 4u);
	EXPECT_EQ(c.estimated().size(), 5u);
	EXPECT_EQ(c.pipelineObj()->framesProcessed(), 5u);

	c.seek(2);  // back: restart and replay 0..2
	EXPECT_EQ(c.currentFrame(), 2);
	EXPECT_EQ(c.estimated().size(), 3u);
	EXPECT_EQ(c.pipelineObj()->framesProcessed(), 3u);
	c.seek(6);  // forward: continue
	EXPECT_EQ(c.currentFrame(), 6);
	EXPECT_EQ(c.pipelineObj()->framesProcessed(), 7u);
}

TEST(ReplayController, PlayClockFollowsDataTimeAndSpeed)
{
	auto o = sampleOptions();
	o.runPipeline = false;  // timing logic only
	ReplayController c(o);
	EXPECT_EQ(c.advance(1.0), 0u);  // paused: nothing
	c.setPlaying(true);
	EXPECT_EQ(c.advance(0.0, 100), 1u);  // frame 0 at once
	EXPECT_EQ(c.currentFrame(), 0);
	// 0.51 s of data at 30 fps: frames 1..15
	EXPECT_EQ(c.advance(0.51, 100), 15u);
	EXPECT_EQ(c.currentFrame(), 15);
	c.setSpeed(2.0);
	EXPECT_EQ(c.advance(0.1, 100), 6u);  // 0.2 s of data
	EXPECT_EQ(c.currentFrame(), 21);
	c.setSpeed(100);  // clamped
	EXPECT_DOUBLE_EQ(c.speed(), 20.0);
	// maxSteps = 1: a slow consumer lags but never skips frames
	EXPECT_EQ(c.advance(10.0, 1), 1u);
	EXPECT_EQ(c.currentFrame(), 22);
	c.seek(149);
	EXPECT_TRUE(c.atEnd());
	c.setPlaying(true);  // at the end: restart from frame 0
	EXPECT_EQ(c.currentFrame(), -1);
	EXPECT_TRUE(c.playing());
}

TEST(ReplayController, PanelsHaveTheFrameSizeAndShowTheMask)
{
	ReplayController c(sampleOptions());
	const auto grey = c.panel(Panel::RgbMask);
	EXPECT_EQ(grey.type(), CV_8UC3);  // before any frame: placeholder
	c.seek(12);
	for (Panel p : {Panel::RgbMask, Panel::Depth, Panel::FlowObserved,
	                Panel::FlowExpected, Panel::Labels})
	{
		const cv::Mat m = c.panel(p);
		EXPECT_EQ(m.cols, 320) << toString(p);
		EXPECT_EQ(m.rows, 240) << toString(p);
		EXPECT_EQ(m.type(), CV_8UC3) << toString(p);
	}
	ASSERT_NE(c.result(), nullptr);
	EXPECT_FALSE(c.result()->flowObserved.empty());
	EXPECT_FALSE(c.result()->flowExpected.empty());
	// The pendulum moves: some pixels are masked, and they are red-tinted.
	const cv::Mat mask = c.currentMask();
	ASSERT_FALSE(mask.empty());
	EXPECT_GT(cv::countNonZero(mask), 50);
	const auto tc = tierColourFractions(c.panel(Panel::Labels));
	EXPECT_GT(tc.red, 0.001);  // Diff labels on the pendulum
	EXPECT_NE(c.statusText().find("frame 12/149"), std::string::npos);
}

TEST(Panels, OverlayTintsOnlyMaskedPixels)
{
	cv::Mat bgr(10, 10, CV_8UC3, cv::Scalar(200, 200, 200));
	cv::Mat mask = cv::Mat::zeros(10, 10, CV_8UC1);
	mask(cv::Rect(2, 2, 4, 4)).setTo(255);
	const cv::Mat o = overlayMask(bgr, mask);
	EXPECT_EQ(o.at<cv::Vec3b>(9, 9), cv::Vec3b(200, 200, 200));
	const auto in = o.at<cv::Vec3b>(3, 3);
	EXPECT_EQ(in, cv::Vec3b(100, 100, 228));                 // 50 % red tint
	EXPECT_EQ(o.at<cv::Vec3b>(2, 2), cv::Vec3b(0, 0, 255));  // outline
	const auto tc = tierColourFractions(o);
	EXPECT_NEAR(tc.red, 16.0 / 100, 1e-9);
	EXPECT_EQ(tc.blue, 0);
	EXPECT_EQ(tc.yellow, 0);
}

TEST(Panels, FlowColourCodesDirectionAndMagnitude)
{
	cv::Mat f(2, 2, CV_32FC2, cv::Scalar(0, 0));
	f.at<cv::Vec2f>(0, 0) = cv::Vec2f(4, 0);
	f.at<cv::Vec2f>(0, 1) = cv::Vec2f(-4, 0);
	f.at<cv::Vec2f>(1, 1) = cv::Vec2f(NAN, NAN);
	const cv::Mat c = flowColour(f, 4, {2, 2});
	EXPECT_EQ(c.at<cv::Vec3b>(1, 1), cv::Vec3b(0, 0, 0));     // none: black
	EXPECT_EQ(c.at<cv::Vec3b>(1, 0), cv::Vec3b(0, 0, 0));     // zero flow
	EXPECT_NE(c.at<cv::Vec3b>(0, 0), c.at<cv::Vec3b>(0, 1));  // direction
	const auto a = c.at<cv::Vec3b>(0, 0);
	EXPECT_EQ(std::max({a[0], a[1], a[2]}), 255);  // full magnitude
	EXPECT_EQ(flowColour(cv::Mat(), 1, {3, 2}).size(), cv::Size(3, 2));
}

TEST(ReplayController, ResultsFolderGivesPosesAndMasks)
{
	const std::string dir =
	    std::string(BIMS_BINARY_DIR) + "/test_viewer_results";
	makeDirs(dir + "/masks");
	ReplaySource src(kRawlog, {});
	Trajectory traj;
	for (size_t i = 0; i < 3; ++i)
		traj.push_back({src.frameTimes()[i],
		                mrpt::poses::CPose3D(0.1 * i, 0, 0, 0, 0, 0)});
	saveTumTrajectory(dir + "/trajectory.txt", traj);
	cv::Mat m = cv::Mat::zeros(240, 320, CV_8UC1);
	m(cv::Rect(10, 10, 20, 20)).setTo(255);
	cv::imwrite(dir + "/masks/000001.png", m);

	ViewerOptions o;
	o.rawlog = kRawlog;
	o.resultsDir = dir;
	o.runPipeline = false;
	ReplayController c(o);
	EXPECT_EQ(c.estimated().size(), 3u);
	c.seek(1);
	EXPECT_NEAR(c.currentPose().x(), 0.1, 1e-6);
	EXPECT_EQ(cv::countNonZero(c.currentMask()), 400);
	c.step();  // no mask file for frame 2
	EXPECT_TRUE(c.currentMask().empty());

	o.resultsDir = dir + "/masks";  // not a results folder
	EXPECT_THROW(ReplayController bad(o), std::runtime_error);
}

TEST(ReplayController, OffscreenViewShowsTheThreeTierColours)
{
	auto o = sampleOptions();
	ReplayController c(o);
	c.layers() = LayerVisibility::parse("all");
	c.seek(14);
	ASSERT_NE(c.result(), nullptr);
	ASSERT_GT(c.pipelineObj()->grids().background()->movingCells().size(), 0u);
	ASSERT_GT(c.pipelineObj()->grids().flowConsistency()->movingCells().size(),
	          0u);
	const auto img = c.renderOffscreen(c.suggestedCamera(), 640, 480);
	ASSERT_EQ(img.getWidth(), 640u);
	img.saveToFile(std::string(BIMS_BINARY_DIR) + "/test_viewer_offscreen.png");
	const auto tc = tierColourFractions(img.asCvMatRef());
	EXPECT_GT(tc.blue, 0.002);
	EXPECT_GT(tc.yellow, 0.0002);
	EXPECT_GT(tc.red, 0.0002);

	// Each tier toggled off disappears from the picture.
	for (Layer l : {Layer::Tier0, Layer::Tier1, Layer::Tier2, Layer::Cloud})
		c.layers()[l] = false;
	const auto none = tierColourFractions(
	    c.renderOffscreen(c.suggestedCamera(), 320, 240).asCvMatRef());
	EXPECT_LT(none.blue, 0.0005);
	EXPECT_LT(none.yellow, 0.0005);
	EXPECT_LT(none.red, 0.0005);
}

// What moves is shown first: by default the static tier-0 voxels are off,
// the cloud's moving points are pure red; with tier 0 on, drawn as faint
// points, the red stays visible (the static voxels do not cover it).
TEST(ReplayController, ByDefaultTheViewShowsWhatMovesAndNotTheStaticMap)
{
	ReplayController c(sampleOptions());
	EXPECT_FALSE(c.layers()[Layer::Tier0]);
	c.seek(30);
	ASSERT_GT(cv::countNonZero(c.currentMask()), 50);
	const auto v = c.view();
	EXPECT_EQ(v->frame, 30);
	EXPECT_EQ(v->counter, "30 / 149");
	EXPECT_EQ(v->status.rfind("frame 30/149", 0), 0u) << v->status;
	EXPECT_EQ(v->layer(Layer::Tier0), nullptr);  // not even built
	ASSERT_NE(v->layer(Layer::Cloud), nullptr);
	// the cloud alone: its moving points are red
	LayerVisibility cloudOnly = LayerVisibility::parse("cloud");
	mrpt::opengl::COpenGLScene scene;
	showView(scene, *v, cloudOnly);
	ASSERT_NE(scene.getByName("cloud"), nullptr);
	c.layers() = cloudOnly;
	const auto cloud = tierColourFractions(
	    c.renderOffscreen(c.suggestedCamera(), 640, 480).asCvMatRef());
	EXPECT_GT(cloud.red, 0.001);

	c.layers() = LayerVisibility();  // the default
	const auto defImg = c.renderOffscreen(c.suggestedCamera(), 640, 480);
	defImg.saveToFile(std::string(BIMS_BINARY_DIR) +
	                  "/test_viewer_default.png");
	const auto def = tierColourFractions(defImg.asCvMatRef());
	c.layers()[Layer::Tier0] = true;
	const auto withT0 = tierColourFractions(
	    c.renderOffscreen(c.suggestedCamera(), 640, 480).asCvMatRef());
	EXPECT_GT(withT0.blue, 0.002);  // the faint static map is there
	EXPECT_GT(def.red, 0.002);
	EXPECT_GT(withT0.red, 0.7 * def.red) << "static voxels hide what moves";
}

TEST(LayerVisibility, ParsesNamesAndRefusesUnknownOnes)
{
	const auto v = LayerVisibility::parse("cloud,tier2,gt");
	EXPECT_TRUE(v[Layer::Cloud]);
	EXPECT_TRUE(v[Layer::Tier2]);
	EXPECT_TRUE(v[Layer::GroundTruth]);
	EXPECT_FALSE(v[Layer::Tier0]);
	EXPECT_FALSE(v[Layer::Estimated]);
	EXPECT_TRUE(LayerVisibility::parse("all")[Layer::Tier0]);
	EXPECT_FALSE(LayerVisibility::parse("none")[Layer::Cloud]);
	try
	{
		LayerVisibility::parse("cloud,tier3");
		FAIL() << "no throw";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("'tier3'"), std::string::npos);
		EXPECT_NE(std::string(e.what()).find("tier0"), std::string::npos);
	}
}

namespace
{
/** The bundled sample's first 40 frames with what the ordering rule must
 * handle: a 3D scan repeated out of order after scan #10 (skipped), and an
 * IMU sample whose angular rate is NaN (not used, its frame flagged). */
std::string sampleWithFaults(const std::string& test, bool depthOnly = false)
{
	// a folder per test: CTest runs them in parallel
	const std::string path =
	    bims::test::freshTmpDir("bims_test_viewer", test) + "/in.rawlog";
	RawlogReader in(kRawlog);
	RawlogWriter out(path);
	std::vector<mrpt::obs::CObservation::Ptr> scans;
	size_t imu = 0;
	while (auto o = in.next())
	{
		if (auto s =
		        std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
		            o))
		{
			if (scans.size() == 40) break;
			if (depthOnly)
			{
				// a LiDAR or time-of-flight camera without colour
				s->hasIntensityImage = false;
				s->intensityImage = mrpt::img::CImage();
			}
			scans.push_back(s);
			out.write(*s);
			if (scans.size() == 11) out.write(*scans[5]);
		}
		else if (auto m =
		             std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o))
		{
			if (++imu == 60) m->set(mrpt::obs::IMU_WZ, NAN);
			out.write(*m);
		}
	}
	out.close();
	return path;
}

/** What a program saw of one frame. */
struct Seen
{
	size_t index;
	mrpt::poses::CPose3D T_WC;
	cv::Mat mask;
};

/** bims-run's frames of \a input (config/default.ini). \a lookahead false:
 * as live input runs, no frame waiting for the next one (and its IMU
 * samples: the attitudes then differ in their last bits). */
std::vector<Seen> batchFrames(const std::string& input, bool lookahead = true)
{
	pipeline::ExperimentConfig cfg;
	cfg.loadFromFile(kConfig);
	cfg.pipeline.flow_lookahead = lookahead;
	std::vector<Seen> batch;
	pipeline::RunOptions ro;
	ro.rawlogs = {input};
	ro.onFrame = [&](const pipeline::FrameResult& r, const auto&) {
		batch.push_back({r.index, r.T_WC, r.mask.clone()});
	};
	const auto sum = pipeline::runExperiment(cfg, ro);
	EXPECT_TRUE(sum.error.empty()) << sum.error;
	EXPECT_EQ(sum.scansOutOfOrder, 1u);
	EXPECT_EQ(sum.imuRejected, 1u);
	return batch;
}

void expectSame(const pipeline::FrameResult& r, const Seen& want, size_t k)
{
	EXPECT_EQ(r.index, want.index) << "frame " << k;
	EXPECT_EQ(r.T_WC.asVectorVal(), want.T_WC.asVectorVal()) << "frame " << k;
	ASSERT_EQ(r.mask.size(), want.mask.size()) << "frame " << k;
	EXPECT_EQ(cv::countNonZero(r.mask != want.mask), 0) << "frame " << k;
}
}  // namespace

namespace
{
/** The viewer's replay of \a input gives \a batch's frames; \a check (if
 * any) looks at each result too. */
void expectReplaySame(
    const std::string& input, const std::vector<Seen>& batch,
    const std::function<void(const pipeline::FrameResult&)>& check = {})
{
	ViewerOptions o;
	o.rawlog = input;
	o.configPath = kConfig;
	ReplayController c(o);
	EXPECT_EQ(c.frameCount(), batch.size());
	size_t k = 0;
	while (c.step())
	{
		ASSERT_LT(k, batch.size());
		const auto* r = c.result();
		ASSERT_NE(r, nullptr);
		if (check) check(*r);
		expectSame(*r, batch[k], k);
		++k;
	}
	EXPECT_EQ(k, batch.size());
}

/** Live segmentation of \a input's observations, handed over one by one as a
 * live sensor would, gives \a batch's frames; returns its order statistics. */
source::FrameOrderStats expectLiveSame(const std::string& input,
                                       const std::vector<Seen>& batch)
{
	pipeline::ExperimentConfig cfg;
	cfg.loadFromFile(kConfig);
	pipeline::LiveSegmentation live(cfg, "test", "live input");
	size_t k = 0;
	const auto onFrame =
	    [&](const source::SourceFrame&, const pipeline::FrameResult& r)
	{
		ASSERT_LT(k, batch.size());
		expectSame(r, batch[k], k);
		++k;
	};
	RawlogReader in(input);
	while (auto o = in.next()) live.push(o, onFrame);
	live.finish(onFrame);
	EXPECT_EQ(k, batch.size());
	return live.stats();
}
}  // namespace

TEST(BatchAndReplay, GiveTheSameFramesPosesAndMasks)
{
	const std::string input = sampleWithFaults("batch_and_replay");
	const auto batch = batchFrames(input);
	ASSERT_EQ(batch.size(), 40u);
	expectReplaySame(input, batch);
}

// The same for a recording without colour: depth-only frames run the same
// way in the three programs.
TEST(BatchReplayAndLive, DepthOnlyFramesAreTheSameInAllThree)
{
	const std::string input = sampleWithFaults("depth_only", true);
	const auto batch = batchFrames(input);
	ASSERT_EQ(batch.size(), 40u);
	expectReplaySame(input, batch,
	                 [](const pipeline::FrameResult& r)
	                 { EXPECT_TRUE(r.flowOff); });
	expectLiveSame(input, batchFrames(input, false));
}

TEST(BatchAndLive, GiveTheSameFramesPosesAndMasks)
{
	const std::string input = sampleWithFaults("batch_and_live");
	const auto batch = batchFrames(input, false);
	EXPECT_EQ(expectLiveSame(input, batch).scansOutOfOrder, 1u);
}

namespace
{
/** The sample's first 40 frames with their IMU samples, in a folder of
 * \a test (the worker tests play it to its end: 40 frames keep them short
 * under the sanitizers). */
ViewerOptions shortSample(const std::string& test)
{
	const std::string path =
	    bims::test::freshTmpDir("bims_test_viewer", test) + "/in.rawlog";
	RawlogReader in(kRawlog);
	RawlogWriter out(path);
	size_t scans = 0;
	while (auto o = in.next())
	{
		if (IS_CLASS(*o, mrpt::obs::CObservation3DRangeScan) && ++scans > 40)
			break;
		out.write(*o);
	}
	out.close();
	ViewerOptions v = sampleOptions();
	v.rawlog = path;
	return v;
}

/** The moving masks of \a o's frames, as the controller alone (on this
 * thread) shows them. */
std::vector<cv::Mat> controllerMasks(const ViewerOptions& o)
{
	ReplayController c(o);
	std::vector<cv::Mat> masks;
	while (c.step()) masks.push_back(c.currentMask().clone());
	return masks;
}

bool sameMask(const cv::Mat& a, const cv::Mat& b)
{
	return a.size() == b.size() && (a.empty() || cv::countNonZero(a != b) == 0);
}
}  // namespace

// Every frame: a GUI that draws each view it gets sees every frame, in
// order, with the masks the controller gives on one thread.
TEST(ReplayWorker, EveryFrameModeDrawsEveryFrameWithTheSameMasks)
{
	const auto o = shortSample("every_frame");
	const auto want = controllerMasks(o);
	ASSERT_EQ(want.size(), 40u);
	ReplayWorker w(o, LayerVisibility());
	EXPECT_EQ(w.frameCount(), 40u);
	w.setMode(PlayMode::EveryFrame);
	w.setSpeed(20);
	w.play(true);
	std::vector<long> seen;
	uint64_t last = 0;
	// (a generous wall-time limit: sanitizer builds run 3-10x slower)
	const auto until =
	    std::chrono::steady_clock::now() + std::chrono::minutes(8);
	while ((seen.empty() || seen.back() < 39) &&
	       std::chrono::steady_clock::now() < until)
	{
		const auto v = w.latest();
		if (!v || v->seq == last)
		{
			std::this_thread::sleep_for(std::chrono::microseconds(200));
			continue;
		}
		last = v->seq;
		if (v->frame >= 0)
		{
			seen.push_back(v->frame);
			EXPECT_TRUE(sameMask(v->mask, want[size_t(v->frame)]))
			    << "frame " << v->frame;
			EXPECT_EQ(v->counter, std::to_string(v->frame) + " / 39");
		}
		w.drawn(v->seq);
	}
	ASSERT_EQ(seen.size(), 40u);
	for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], long(i));
	ASSERT_TRUE(w.waitIdle(30));
	EXPECT_EQ(w.state().processed, 40u);
	EXPECT_EQ(w.state().notDrawn, 0u);
	EXPECT_FALSE(w.state().playing);  // stopped at the end
	EXPECT_EQ(w.takeError(), "");
}

// Real time: a GUI that never finishes drawing does not hold the pipeline
// back; every frame is processed, those finished while the GUI was busy are
// counted as not drawn, and the newest is drawn once the GUI is free.
TEST(ReplayWorker, RealTimeModeNeverWaitsForTheGui)
{
	ReplayWorker w(shortSample("real_time"), LayerVisibility());
	w.setSpeed(20);
	w.play(true);
	ASSERT_TRUE(w.waitIdle(300));
	const auto st = w.state();
	EXPECT_EQ(st.processed, 40u);
	EXPECT_FALSE(st.playing);
	auto v = w.latest();
	ASSERT_NE(v, nullptr);
	EXPECT_EQ(v->seq, 1u);  // the only view built: the GUI never drew it
	EXPECT_LE(v->frame, 0);
	// frames 1..38 were finished while that view was still being drawn
	EXPECT_EQ(st.notDrawn, v->frame < 0 ? 39u : 38u);
	w.drawn(v->seq);
	ASSERT_TRUE(w.waitIdle(30));
	v = w.latest();
	EXPECT_EQ(v->frame, 39);  // the newest, once the GUI is free
	EXPECT_EQ(v->seq, 2u);
}

// Step, seek and restart run on the replay thread and are exact; a seek
// is interrupted by a later one; the layers are rebuilt on request.
TEST(ReplayWorker, StepSeekAndRestartAreExact)
{
	const auto o = shortSample("step_seek");
	const auto want = controllerMasks(o);
	ReplayWorker w(o, LayerVisibility());
	const auto settle = [&]
	{
		for (int i = 0; i < 100; ++i)  // the GUI draws whatever comes
		{
			EXPECT_TRUE(w.waitIdle(30));
			const auto v = w.latest();
			if (!v) continue;
			w.drawn(v->seq);
			if (w.waitIdle(0.01) && w.latest()->seq == v->seq) return v;
		}
		ADD_FAILURE() << "never settled";
		return w.latest();
	};
	w.step();
	w.step();
	w.step();
	auto v = settle();
	EXPECT_EQ(v->frame, 2);
	EXPECT_TRUE(sameMask(v->mask, want[2]));
	w.seek(35);
	w.seek(25);  // interrupts (or follows) the first
	v = settle();
	EXPECT_EQ(v->frame, 25);
	EXPECT_TRUE(sameMask(v->mask, want[25]));
	EXPECT_EQ(w.state().processed, 26u);
	w.seek(12);  // back: the pipeline restarts and runs 0..12
	v = settle();
	EXPECT_EQ(v->frame, 12);
	EXPECT_TRUE(sameMask(v->mask, want[12]));
	w.withController([](ReplayController& c)
	                 { EXPECT_EQ(c.pipelineObj()->framesProcessed(), 13u); });
	EXPECT_EQ(v->layer(Layer::Tier0), nullptr);
	w.setLayers(LayerVisibility::parse("all"));
	v = settle();
	EXPECT_EQ(v->frame, 12);
	EXPECT_NE(v->layer(Layer::Tier0), nullptr);
	w.restart();
	v = settle();
	EXPECT_EQ(v->frame, 0);
	EXPECT_TRUE(sameMask(v->mask, want[0]));
	w.seek(39);  // the destructor stops a seek
}
