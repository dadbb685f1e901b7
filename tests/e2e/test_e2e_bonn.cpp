// End-to-end on real data: the people-free frames 0-59 of the Bonn sample
// (BIMS_SHARED_DATA_DIR/bonn_crowd_f150_349) must be labelled almost
// entirely static by the flow labels (flow-only variant, config/bonn.ini,
// vision-only egomotion: the recording has no IMU), while frames with
// walking people are not. Frames are read straight from the TUM folder
// (no rawlog written). Figures in docs/journal/pipeline.md.
#include <bims/ego/depth_correction.h>
#include <bims/eval/mask_labels.h>
#include <bims/eval/mask_metrics.h>
#include <bims/eval/tum_import.h>
#include <bims/pipeline/pipeline.h>
#include <bims_test/data.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>

#include <cstdio>
#include <filesystem>

using namespace bims::pipeline;

namespace
{
const std::string kConfig = std::string(BIMS_SOURCE_DIR) + "/config/bonn.ini";

/** The slice as config/bonn.ini imports it. */
struct Slice
{
	bims::eval::ImportParams ip;
	bims::eval::TumFolder folder;
};
Slice loadSlice()
{
	mrpt::config::CConfigFile file(kConfig);
	Slice s;
	s.ip.loadFromConfigFile(file);
	s.folder = bims::eval::readTumFolder(bims::test::kBonnCrowd, s.ip);
	return s;
}
/** config/bonn.ini, vision-only egomotion (the recording has no IMU). */
ExperimentConfig visionConfig()
{
	ExperimentConfig cfg;
	cfg.loadFromFile(kConfig);
	cfg.ego.odometry.mode = bims::ego::OdometryMode::Vision;
	cfg.ego.odometry.gyro_aid = false;
	return cfg;
}

/** Mean over the non-warm-up frames [first, last] of the moving share of the
 * valid-depth pixels. */
double meanMovingFraction(const ExperimentConfig& cfg,
                          const bims::eval::TumFolder& folder,
                          const bims::eval::ImportParams& ip, size_t first,
                          size_t last)
{
	Pipeline pipe(cfg);
	double sum = 0;
	size_t n = 0;
	for (size_t i = first; i <= last; i++)
	{
		const auto scan = bims::eval::loadFrame(folder.frames.at(i), ip);
		const FrameResult& r = pipe.processFrame(*scan, i);
		if (r.warmup) continue;
		cv::Mat valid(scan->rangeImage.rows(), scan->rangeImage.cols(),
		              CV_8UC1);
		for (int v = 0; v < valid.rows; v++)
			for (int u = 0; u < valid.cols; u++)
				valid.at<uint8_t>(v, u) = scan->rangeImage(v, u) > 0 ? 255 : 0;
		const double nValid = cv::countNonZero(valid);
		if (nValid > 0)
		{
			sum += cv::countNonZero(r.mask & valid) / nValid;
			n++;
		}
	}
	return n ? sum / n : 0;
}
/** Scores of every frame of \a folder against the masks_proxy labels
 * (255 moving, 0 static, 150 and 50 not scored), paired by time stamp as
 * bims-eval masks pairs them; \a peopleFree gets the frames without a
 * moving label. */
bims::eval::MaskMetrics scoreAgainstProxy(const ExperimentConfig& cfg,
                                          const bims::eval::TumFolder& folder,
                                          const bims::eval::ImportParams& ip,
                                          bims::eval::MaskMetrics* peopleFree)
{
	namespace ev = bims::eval;
	const auto labels =
	    ev::listMaskFiles(bims::test::kBonnCrowd + "/masks_proxy");
	const auto conv = ev::LabelConvention::explicitValues(255, 0, {150, 50});
	Pipeline pipe(cfg);
	// the depth correction of config/bonn.ini, as bims-run applies it
	bims::sensors::DepthCorrection depthCorrection(cfg.ego.depth_correction);
	std::vector<ev::MaskFile> preds;
	std::vector<cv::Mat> masks;
	for (size_t i = 0; i < folder.frames.size(); i++)
	{
		const auto scan = bims::eval::loadFrame(folder.frames[i], ip);
		depthCorrection.apply(*scan, cfg.ego.camera);
		const FrameResult& r = pipe.processFrame(*scan, i);
		ev::MaskFile f;
		f.name = std::to_string(i);
		f.stamp = r.t;
		preds.push_back(f);
		masks.push_back(r.mask.clone());
	}
	const auto match = ev::matchMasks(labels, preds, {}, 0.01);
	EXPECT_EQ(match.pairs.size(), 200u);
	EXPECT_TRUE(match.predictionsWithoutLabel.empty());
	ev::MaskMetrics total;
	for (const auto& p : match.pairs)
	{
		const cv::Mat l = ev::loadMask(bims::test::kBonnCrowd +
		                               "/masks_proxy/" + p.label->name);
		const auto m = ev::MaskMetrics::compute(
		    l, masks[static_cast<size_t>(p.pred - preds.data())], cv::Mat(),
		    conv);
		total += m;
		if (peopleFree && m.tp + m.fn == 0) *peopleFree += m;
	}
	return total;
}
}  // namespace

TEST(BonnEndToEnd, SegmentationAgainstProxyLabels)
{
	// The real-data configuration (config/bonn.ini, its variant) against
	// the per-pixel labels of the slice, and the single-cue variants beside
	// it. Figures of bench/segmentation_real.sh in docs/results.md.
	if (!std::filesystem::exists(bims::test::kBonnCrowd + "/masks_proxy"))
		GTEST_SKIP() << "no Bonn labels at " << bims::test::kBonnCrowd;
	const auto [ip, folder] = loadSlice();
	const ExperimentConfig cfg = visionConfig();
	bims::eval::MaskMetrics free;
	const auto chosen = scoreAgainstProxy(cfg, folder, ip, &free);
	std::printf(
	    "config/bonn.ini: %s, static called moving %.3f %% (frames "
	    "without people %.3f %%)\n",
	    chosen.scoresLine().c_str(), 100 * chosen.staticAsMoving(),
	    100 * free.staticAsMoving());
	// issue 14's targets: F1 >= 0.85, <= 2 % of static pixels, <= 1 % on
	// the frames without people
	EXPECT_GT(chosen.f1(), 0.85);
	EXPECT_LT(chosen.staticAsMoving(), 0.02);
	EXPECT_LT(free.staticAsMoving(), 0.01);
#if defined(__SANITIZE_ADDRESS__)
	// make test-sanitize: the three comparison runs below are the same code
	// on the same frames (4 minutes more under AddressSanitizer)
	std::printf("AddressSanitizer build: comparison runs skipped\n");
	return;
#endif
	// The paper's claim on real data: fused against each cue alone (same
	// grid model). It beats the flow alone on F1; against the bottom tier
	// alone F1 is a tie (measured 0.9953 vs 0.9957) and the fusion halves
	// the false alarms.
	ExperimentConfig flowOnly = cfg, bottomOnly = cfg, frustum = cfg;
	flowOnly.setVariant(Variant::FlowOnly);
	bottomOnly.setVariant(Variant::BottomOnly);
	const auto mFlow = scoreAgainstProxy(flowOnly, folder, ip, nullptr);
	const auto mBottom = scoreAgainstProxy(bottomOnly, folder, ip, nullptr);
	std::printf(
	    "flow-only: %s\nbottom-only: %s, static called moving "
	    "%.3f %%\n",
	    mFlow.scoresLine().c_str(), mBottom.scoresLine().c_str(),
	    100 * mBottom.staticAsMoving());
	EXPECT_GT(chosen.f1(), mFlow.f1() + 0.2);
	EXPECT_NEAR(chosen.f1(), mBottom.f1(), 0.01);
	EXPECT_LT(chosen.staticAsMoving(), mBottom.staticAsMoving());
	// the reason for decay = raycast in config/bonn.ini
	frustum.grids.decay = bims::maps::DecayMode::Frustum;
	const auto mFrustum = scoreAgainstProxy(frustum, folder, ip, nullptr);
	std::printf("decay=frustum: %s\n", mFrustum.scoresLine().c_str());
	EXPECT_GT(chosen.f1(), mFrustum.f1() + 0.1);
}

TEST(BonnEndToEnd, FlowLabelsKeepTheStaticRoomStaticAndSeePeople)
{
	if (!std::filesystem::exists(bims::test::kBonnCrowd + "/depth.txt"))
		GTEST_SKIP() << "no Bonn sample at " << bims::test::kBonnCrowd;
	const auto [ip, folder] = loadSlice();
	ASSERT_EQ(folder.frames.size(), 200u);

	ExperimentConfig cfg = visionConfig();
	cfg.setVariant(Variant::FlowOnly);

	// Measured (VGA, this commit): 0.27 % on frames 0-59; without the texture
	// gate and the dense-flow refinement (and with a synthetic IMU) 29 %.
	const double still = meanMovingFraction(cfg, folder, ip, 0, 59);
	std::printf("frames 0-59 (static room): mean moving fraction %.3f %%\n",
	            100 * still);
	EXPECT_LT(still, 0.01);

	// Frames 160-169: people walk through most of the view. Measured 31 %.
	const double people = meanMovingFraction(cfg, folder, ip, 159, 169);
	std::printf("frames 160-169 (people): mean moving fraction %.2f %%\n",
	            100 * people);
	EXPECT_GT(people, 0.10);
}
