// End-to-end on a real phone capture (BIMS_SHARED_DATA_DIR/stray_early:
// iPhone LiDAR depth + accelerometer + gyro, no colour, no magnetometer):
// imported with config/stray.ini, run by bims-run's runExperiment with the
// same preset, its trajectory against ARKit's poses and its masks against the
// capture's proxy labels. Regression floors of the figures of
// bench/stray_real.sh (docs/journal/phone-lidar-imu.md).
#include <bims/ego/flags.h>
#include <bims/eval/mask_labels.h>
#include <bims/eval/mask_metrics.h>
#include <bims/eval/stray_import.h>
#include <bims/eval/trajectory_metrics.h>
#include <bims/io/trajectory.h>
#include <bims/pipeline/run.h>
#include <bims_test/data.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>

#include <cstdio>
#include <filesystem>

using namespace bims::pipeline;
namespace ev = bims::eval;

TEST(StrayEndToEnd, DepthAndImuTrackAndSegmentWithoutColour)
{
	if (!std::filesystem::exists(bims::test::kStrayEarly + "/masks_proxy"))
		GTEST_SKIP() << "no Stray capture at " << bims::test::kStrayEarly;
	const std::string config =
	    std::string(BIMS_SOURCE_DIR) + "/config/stray.ini";
	const std::string dir =
	    bims::test::freshTmpDir("bims_test_e2e_stray", "run");
	ev::StrayImportParams ip;
	{
		mrpt::config::CConfigFile f(config);
		ip.loadFromConfigFile(f);
	}
	ev::StrayImportOptions io;
	const auto imp =
	    ev::importStray(bims::test::kStrayEarly, dir + "/s.rawlog", ip, io);
	ASSERT_EQ(imp.frames, 331u);
	ASSERT_FALSE(imp.colour);

	ExperimentConfig cfg;
	cfg.loadFromFile(config);
	RunOptions opt;
	opt.rawlogs = {dir + "/s.rawlog"};
	bims::Trajectory est;
	std::vector<ev::MaskFile> preds;
	std::vector<cv::Mat> masks;
	size_t noImage = 0, measured = 0;
	opt.onFrame = [&](const FrameResult& r, const auto&)
	{
		est.push_back({r.t, r.T_WC});
		ev::MaskFile f;
		f.name = std::to_string(r.index);
		f.stamp = r.t;
		preds.push_back(f);
		masks.push_back(r.mask.clone());
		noImage += (r.ego.flags & bims::ego::kFlagNoImage) != 0;
		measured += r.index > 0 && r.ego.ok();
	};
	const auto sum = runExperiment(cfg, opt);
	ASSERT_TRUE(sum.error.empty()) << sum.error;
	EXPECT_EQ(sum.framesWithoutFlow, 331u);
	EXPECT_EQ(noImage, 331u);
	// no magnetometer was there: nothing says it is missing
	EXPECT_EQ(sum.framesFlaggedBy.count("mag_gated"), 0u);
	EXPECT_EQ(sum.framesFlaggedBy.count("imu_missing"), 0u);
	// every frame measured but the flagged ones (no frame lost silently)
	const size_t failed = sum.framesFlaggedBy.count("anchor_failed")
	                          ? sum.framesFlaggedBy.at("anchor_failed")
	                          : 0;
	EXPECT_EQ(measured + failed, 330u);
	EXPECT_LE(failed, 3u);

	const double ate = ev::computeAte(imp.reference, est).stats.rmse;
	// measured 0.029 m (target 0.05)
	EXPECT_LT(ate, 0.05);

	const auto labels =
	    ev::listMaskFiles(bims::test::kStrayEarly + "/masks_proxy");
	const auto conv = ev::LabelConvention::explicitValues(255, 0, {150, 50});
	const auto match = ev::matchMasks(labels, preds, {}, 0.005);
	EXPECT_EQ(match.pairs.size(), 292u);
	ev::MaskMetrics total, peopleFree;
	for (const auto& p : match.pairs)
	{
		const cv::Mat l = ev::loadMask(bims::test::kStrayEarly +
		                               "/masks_proxy/" + p.label->name);
		const auto m = ev::MaskMetrics::compute(
		    l, masks[static_cast<size_t>(p.pred - preds.data())], cv::Mat(),
		    conv);
		total += m;
		if (m.tp + m.fn == 0) peopleFree += m;
	}
	std::printf(
	    "stray_early, config/stray.ini: ATE %.4f m, %s, static called moving "
	    "%.3f %% on the frames without people\n",
	    ate, total.scoresLine().c_str(), 100 * peopleFree.staticAsMoving());
	// measured F1 0.557 (target 0.80: not met), 0.51 % (target <= 1 %)
	EXPECT_GT(total.f1(), 0.5);
	EXPECT_LT(peopleFree.staticAsMoving(), 0.01);
}
