// The pipeline's stages on the bundled sample: a frame decoded by the caller
// gives what its scan gives; the stepper holds a frame until the one after
// it is at hand (look-ahead) and hands back each frame with its result; the
// threads change no result; a frame of the wrong kind is refused naming it.
#include <bims/pipeline/pipeline.h>
#include <bims/pipeline/stepper.h>
#include <bims/source/frame_source.h>
#include <bims_test/sample.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <stdexcept>
#include <string>
#include <vector>

using namespace bims;
using pipeline::ExperimentConfig;
using pipeline::FrameResult;
using pipeline::FrameStepper;
using pipeline::Pipeline;

namespace
{
constexpr size_t kFrames = 14;  // past the warm-up, with moving voxels

/** What a frame produced, kept for comparison. */
struct Seen
{
	size_t index = 0;
	cv::Mat mask, labels;
	mrpt::poses::CPose3D T_WC;
	size_t movingVoxels = 0, hitVoxels = 0;
};

Seen keep(const FrameResult& r)
{
	return {r.index, r.mask.clone(), r.labels.clone(),
	        r.T_WC,  r.movingVoxels, r.hitVoxels};
}

bool same(const cv::Mat& a, const cv::Mat& b)
{
	return a.size() == b.size() && a.type() == b.type() &&
	       (a.empty() || cv::norm(a, b, cv::NORM_INF) == 0);
}

void expectSame(const Seen& a, const Seen& b)
{
	EXPECT_EQ(a.index, b.index);
	EXPECT_TRUE(same(a.mask, b.mask)) << "mask of frame " << a.index;
	EXPECT_TRUE(same(a.labels, b.labels)) << "labels of frame " << a.index;
	EXPECT_EQ(a.T_WC.asString(), b.T_WC.asString()) << "frame " << a.index;
	EXPECT_EQ(a.movingVoxels, b.movingVoxels) << "frame " << a.index;
	EXPECT_EQ(a.hitVoxels, b.hitVoxels) << "frame " << a.index;
}

ExperimentConfig config(bool threads)
{
	ExperimentConfig cfg;
	cfg.loadFromFile(test::kDefaultConfig);
	cfg.pipeline.flow_thread = threads;
	cfg.pipeline.flow_lookahead = threads;
	cfg.pipeline.cloud_thread = threads;
	return cfg;
}

/** The sample's first kFrames frames, with their IMU samples. */
std::vector<source::SourceFrame> sampleFrames(const ExperimentConfig& cfg)
{
	auto order = source::FrameOrderParams::of(cfg.ego, cfg.pipeline.imu_wait_s,
	                                          "test_pipeline_stages");
	source::RawlogFrameSource src({test::kSample}, order, false);
	std::vector<source::SourceFrame> frames;
	while (frames.size() < kFrames)
	{
		auto f = src.next();
		if (!f) break;
		frames.push_back(std::move(*f));
	}
	EXPECT_EQ(frames.size(), kFrames) << src.error();
	return frames;
}

/** Each frame run by processFrame(scan), in sequence, without look-ahead. */
std::vector<Seen> runScans(const ExperimentConfig& cfg)
{
	Pipeline pipe(cfg);
	std::vector<Seen> out;
	for (const auto& f : sampleFrames(cfg))
	{
		for (const auto& m : f.imu) pipe.addImu(*m);
		out.push_back(keep(pipe.processFrame(*f.scan, f.index)));
	}
	return out;
}
}  // namespace

TEST(PipelineStages, AFrameDecodedByTheCallerGivesWhatItsScanGives)
{
	const ExperimentConfig cfg = config(false);
	const std::vector<Seen> scans = runScans(cfg);
	ASSERT_EQ(scans.size(), kFrames);
	size_t moving = 0;
	for (const auto& s : scans) moving += s.movingVoxels;
	ASSERT_GT(moving, 0u) << "the sample's pendulum is never found";

	Pipeline pipe(cfg);
	// the caller's frames, and copies of their images
	std::vector<ego::RgbdFrame> given;
	std::vector<std::vector<cv::Mat>> before;
	for (const auto& f : sampleFrames(cfg))
	{
		for (const auto& m : f.imu) pipe.addImu(*m);
		ego::RgbdFrame frame;
		ASSERT_EQ(ego::rgbdFrameFrom(*f.scan, cfg.ego.camera, frame), "");
		expectSame(keep(pipe.processFrame(frame, f.index)),
		           scans.at(given.size()));
		before.push_back(
		    {frame.grey.clone(), frame.depth.clone(), frame.raw.clone()});
		given.push_back(frame);
	}
	ASSERT_EQ(given.size(), kFrames);
	// the pipeline read the caller's images and never wrote into them
	for (size_t k = 0; k < kFrames; ++k)
	{
		EXPECT_TRUE(same(given[k].grey, before[k][0])) << "frame " << k;
		EXPECT_TRUE(same(given[k].depth, before[k][1])) << "frame " << k;
		EXPECT_TRUE(same(given[k].raw, before[k][2])) << "frame " << k;
	}
}

TEST(PipelineStages, TheStepperRunsAFrameOnceTheNextIsAtHandWithTheSameResults)
{
	const std::vector<Seen> sequential = runScans(config(false));
	const ExperimentConfig cfg = config(true);
	Pipeline pipe(cfg);
	FrameStepper stepper(pipe);
	std::vector<Seen> stepped;
	auto frames = sampleFrames(cfg);
	for (size_t i = 0; i < frames.size(); ++i)
	{
		stepper.add(std::move(frames[i]));
		auto done = stepper.run();
		// with the look-ahead a frame waits for the one after it
		ASSERT_EQ(done.has_value(), i > 0) << "after adding frame " << i;
		if (!done) continue;
		EXPECT_EQ(done->input.index, i - 1);
		EXPECT_EQ(done->result.index, i - 1);
		EXPECT_EQ(&done->result, &pipe.last());
		EXPECT_FALSE(stepper.run().has_value());  // nothing else is ready
		stepped.push_back(keep(done->result));
		// the frame it ran with its observed flow started ahead
		if (i >= 2)
		{
			EXPECT_TRUE(done->result.flowAhead) << "frame " << i - 1;
		}
	}
	auto last = stepper.run(true);  // the end of the input: the last frame
	ASSERT_TRUE(last.has_value());
	EXPECT_EQ(last->input.index, kFrames - 1);
	stepped.push_back(keep(last->result));
	EXPECT_FALSE(stepper.run(true).has_value());
	ASSERT_EQ(stepped.size(), sequential.size());
	for (size_t k = 0; k < stepped.size(); ++k)
		expectSame(stepped[k], sequential[k]);
}

TEST(PipelineStages, AFrameOfTheWrongKindIsRefusedNamingIt)
{
	const ExperimentConfig cfg = config(false);
	const auto frames = sampleFrames(cfg);
	ego::RgbdFrame good;
	ASSERT_EQ(ego::rgbdFrameFrom(*frames.at(0).scan, cfg.ego.camera, good), "");
	auto refused = [&](ego::RgbdFrame f, const std::string& what)
	{
		Pipeline pipe(cfg);
		try
		{
			pipe.processFrame(f, 7);
			ADD_FAILURE() << "accepted: " << what;
		}
		catch (const std::runtime_error& e)
		{
			const std::string msg = e.what();
			EXPECT_NE(msg.find("#7"), std::string::npos) << msg;
			EXPECT_NE(msg.find(what), std::string::npos) << msg;
		}
		EXPECT_EQ(pipe.framesProcessed(), 0u);
	};
	ego::RgbdFrame f = good;
	f.depth = cv::Mat();
	refused(f, "depth");
	f = good;
	f.depth = cv::Mat(good.depth.size(), CV_64FC1, cv::Scalar(1));
	refused(f, "depth");
	f = good;
	f.raw = cv::Mat(cv::Size(4, 3), CV_16UC1, cv::Scalar(1000));
	refused(f, "raw depth");
	f = good;
	f.grey = cv::Mat(good.depth.rows / 2, good.depth.cols, CV_8UC1);
	refused(f, "image");
	// and the good frame runs
	Pipeline pipe(cfg);
	EXPECT_NO_THROW(pipe.processFrame(good, 0));
	EXPECT_EQ(pipe.framesProcessed(), 1u);
}
