// Label conventions, mask folder naming and the matching of predictions to
// labels by index and by time (bims::eval::matchMasks), on hand-made data.
#include <bims/eval/mask_labels.h>
#include <bims/eval/mask_metrics.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

namespace ev = bims::eval;
namespace fs = std::filesystem;

namespace
{
std::string freshDir(const std::string& name)
{
	const auto d =
	    fs::temp_directory_path() /
	    ("bims_mask_labels_" + name + "_" +
	     std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
	fs::remove_all(d);
	fs::create_directories(d);
	return d.string();
}
void touchPng(const std::string& path)
{
	cv::imwrite(path, cv::Mat(2, 2, CV_8UC1, cv::Scalar(0)));
}
ev::MaskFile byTime(double t)
{
	ev::MaskFile f;
	f.name = std::to_string(t) + ".png";
	f.stamp = t;
	return f;
}
ev::MaskFile byIndex(long k)
{
	ev::MaskFile f;
	f.name = std::to_string(k) + ".png";
	f.index = k;
	return f;
}
}  // namespace

TEST(LabelConvention, ProxyValuesAreScoredIgnoredOrAnError)
{
	const auto c = ev::LabelConvention::explicitValues(255, 0, {150, 50});
	EXPECT_EQ(c.classOf(255), ev::LabelClass::Moving);
	EXPECT_EQ(c.classOf(0), ev::LabelClass::Static);
	EXPECT_EQ(c.classOf(150), ev::LabelClass::NotScored);
	EXPECT_EQ(c.classOf(50), ev::LabelClass::NotScored);
	EXPECT_EQ(c.classOf(128), ev::LabelClass::Unknown);
	EXPECT_EQ(c.describe(), "moving 255, static 0, not scored 150 50");
	// the contract: >= 128 moving, the rest static, nothing unknown
	const ev::LabelConvention contract;
	EXPECT_EQ(contract.classOf(150), ev::LabelClass::Moving);
	EXPECT_EQ(contract.classOf(50), ev::LabelClass::Static);
	const cv::Mat l = (cv::Mat_<uint8_t>(1, 4) << 255, 0, 150, 50);
	cv::Mat moving = l, scored;  // (the output may share the input)
	c.toContract(l, moving, scored);
	EXPECT_EQ(
	    cv::countNonZero(moving == (cv::Mat_<uint8_t>(1, 4) << 255, 0, 0, 0)),
	    4);
	EXPECT_EQ(
	    cv::countNonZero(scored == (cv::Mat_<uint8_t>(1, 4) << 255, 255, 0, 0)),
	    4);
	EXPECT_THROW(ev::LabelConvention::explicitValues(255, 0, {255}),
	             std::invalid_argument);
	EXPECT_THROW(ev::LabelConvention::explicitValues(300, 0, {}),
	             std::invalid_argument);
	EXPECT_EQ(ev::parseLabelValues("150,50"), (std::vector<int>{150, 50}));
	EXPECT_EQ(ev::parseLabelValues("150 50"), (std::vector<int>{150, 50}));
	EXPECT_THROW(ev::parseLabelValues("150,x"), std::invalid_argument);
	EXPECT_THROW(ev::parseLabelValues("256"), std::invalid_argument);
}

TEST(LabelConvention, IgnoredPixelsAreNotScoredAndOtherValuesThrow)
{
	// label: moving, static, ambiguous, no depth; prediction moving on all
	cv::Mat gt = (cv::Mat_<uint8_t>(1, 4) << 255, 0, 150, 50);
	const cv::Mat pred(1, 4, CV_8UC1, cv::Scalar(255));
	const auto c = ev::LabelConvention::explicitValues(255, 0, {150, 50});
	const auto m = ev::MaskMetrics::compute(gt, pred, cv::Mat(), c);
	EXPECT_EQ(m.tp, 1u);
	EXPECT_EQ(m.fp, 1u);
	EXPECT_EQ(m.fn + m.tn, 0u);
	EXPECT_EQ(m.ignored, 2u);
	EXPECT_DOUBLE_EQ(m.staticAsMoving(), 1.0);
	gt.at<uint8_t>(0, 3) = 77;
	try
	{
		ev::MaskMetrics::compute(gt, pred, cv::Mat(), c);
		FAIL() << "an unknown label value must throw";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("label value 77 at pixel (3, 0)"),
		          std::string::npos)
		    << e.what();
	}
}

TEST(LabelConvention, ValueCountsNameTheUnknownValues)
{
	const auto c = ev::LabelConvention::explicitValues(255, 0, {});
	ev::LabelValueCounts n;
	n.add((cv::Mat_<uint8_t>(1, 4) << 255, 0, 150, 150));
	n.add((cv::Mat_<uint8_t>(1, 2) << 0, 50));
	EXPECT_EQ(n.unknown(c), (std::vector<int>{50, 150}));
	EXPECT_EQ(n.firstImage[150], 0u);
	EXPECT_EQ(n.firstImage[50], 1u);
	EXPECT_EQ(n.describe(c),
	          "0: 2 px in 2 of 2 labels (static), 50: 1 px in 1 of 2 labels "
	          "(UNKNOWN), 150: 2 px in 1 of 2 labels (UNKNOWN), 255: 1 px in 1 "
	          "of 2 labels (moving)");
	EXPECT_TRUE(
	    n.unknown(ev::LabelConvention::explicitValues(255, 0, {150, 50}))
	        .empty());
	// a label folder's own declaration
	const auto d = freshDir("conv");
	EXPECT_FALSE(ev::readLabelConventionFile(d).has_value());
	std::ofstream(d + "/labels.ini")
	    << "[labels]\nmoving = 255\nstatic = 0\nnot_scored = 150, 50\n";
	const auto f = ev::readLabelConventionFile(d);
	ASSERT_TRUE(f.has_value());
	EXPECT_EQ(f->describe(), "moving 255, static 0, not scored 150 50");
	std::ofstream(d + "/labels.ini") << "[labels]\nmoving = 255\n";
	EXPECT_THROW(ev::readLabelConventionFile(d), std::runtime_error);
}

TEST(MaskMetrics, AFrameWithoutMovingLabelReportsItsFalsePositivesNotF1)
{
	const cv::Mat gt(1, 4, CV_8UC1, cv::Scalar(0));
	const cv::Mat pred = (cv::Mat_<uint8_t>(1, 4) << 255, 0, 0, 0);
	const auto m = ev::MaskMetrics::compute(gt, pred);
	EXPECT_EQ(m.frameScoresLine(),
	          "no moving label: fp 1, static as moving 0.2500");
	const cv::Mat gt2 = (cv::Mat_<uint8_t>(1, 4) << 255, 0, 0, 0);
	const auto m2 = ev::MaskMetrics::compute(gt2, pred);
	EXPECT_EQ(m2.frameScoresLine(), m2.scoresLine());
}

TEST(MaskFiles, NamedByIndexOrByTimeNotBoth)
{
	const auto d = freshDir("names");
	touchPng(d + "/1548339824.89375.png");
	touchPng(d + "/1548339824.86039.png");
	std::ofstream(d + "/notes.txt") << "not a mask\n";
	const auto f = ev::listMaskFiles(d);
	ASSERT_EQ(f.size(), 2u);
	EXPECT_TRUE(f[0].byTime());
	EXPECT_DOUBLE_EQ(f[0].stamp, 1548339824.86039);  // sorted by time
	touchPng(d + "/000003.png");
	EXPECT_THROW(ev::listMaskFiles(d), std::runtime_error);  // mixed
	fs::remove(d + "/000003.png");
	touchPng(d + "/frame_a.png");
	try
	{
		ev::listMaskFiles(d);
		FAIL() << "a name that is neither must throw";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("frame_a.png"), std::string::npos);
	}
	EXPECT_THROW(ev::listMaskFiles(d + "/none"), std::runtime_error);
}

TEST(MaskFiles, FrameStampsFromARunsCsv)
{
	const auto d = freshDir("csv");
	std::ofstream(d + "/frames.csv")
	    << "index,t,ego_flags\n0,100.000000,3\n1,100.033000,0\n";
	const auto s = ev::readFrameStamps(d + "/frames.csv");
	ASSERT_EQ(s.size(), 2u);
	EXPECT_DOUBLE_EQ(s.at(1), 100.033);
	std::ofstream(d + "/bad.csv") << "index,t\n0,100\n1,abc\n";
	try
	{
		ev::readFrameStamps(d + "/bad.csv");
		FAIL();
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("bad.csv:3:"), std::string::npos)
		    << e.what();
	}
	std::ofstream(d + "/nocol.csv") << "frame,time\n0,1\n";
	EXPECT_THROW(ev::readFrameStamps(d + "/nocol.csv"), std::runtime_error);
}

TEST(MatchMasks, ByTimeOneToOneWithinTheTolerance)
{
	// labels every 33 ms from t = 10; the run dropped the first frame and
	// ran 2 frames past the labels
	std::vector<ev::MaskFile> labels, preds;
	for (int k = 0; k < 5; k++) labels.push_back(byTime(10 + 0.033 * k));
	std::map<long, double> t;
	for (int k = 0; k < 6; k++)
	{
		preds.push_back(byIndex(k));
		t[k] = 10.033 + 0.033 * k + 0.002;  // 2 ms off
	}
	auto m = ev::matchMasks(labels, preds, t, 0.01);
	ASSERT_EQ(m.pairs.size(), 4u);
	EXPECT_EQ(m.pairs[0].label, &labels[1]);
	EXPECT_EQ(m.pairs[0].pred, &preds[0]);
	EXPECT_NEAR(m.pairs[0].dt, 0.002, 1e-9);
	ASSERT_EQ(m.labelsWithoutPrediction.size(), 1u);
	EXPECT_EQ(m.labelsWithoutPrediction[0], &labels[0]);
	// (before the first prediction: outside the run's span)
	ASSERT_EQ(m.labelsOutsidePredictions.size(), 1u);
	EXPECT_EQ(m.predictionsOutside, 2);
	EXPECT_TRUE(m.predictionsWithoutLabel.empty());
	// a label missing inside the span is reported
	labels.erase(labels.begin() + 2);
	m = ev::matchMasks(labels, preds, t, 0.01);
	ASSERT_EQ(m.predictionsWithoutLabel.size(), 1u);
	EXPECT_EQ(m.predictionsWithoutLabel[0], &preds[1]);
	// another run (stamps 1 s later): nothing pairs
	for (auto& [k, s] : t) s += 1;
	m = ev::matchMasks(labels, preds, t, 0.01);
	EXPECT_TRUE(m.pairs.empty());
	// a prediction without a stamp is an error naming it
	t.erase(3);
	EXPECT_THROW(ev::matchMasks(labels, preds, t, 0.01), std::runtime_error);
}

TEST(MatchMasks, ByIndexPairsEqualNames)
{
	const std::vector<ev::MaskFile> labels = {byIndex(0), byIndex(2)},
	                                preds = {byIndex(0), byIndex(1)};
	const auto m = ev::matchMasks(labels, preds, {}, 0.01);
	ASSERT_EQ(m.pairs.size(), 1u);
	EXPECT_EQ(m.pairs[0].label->index, 0);
	ASSERT_EQ(m.labelsWithoutPrediction.size(), 1u);
	EXPECT_EQ(m.labelsWithoutPrediction[0]->index, 2);
	EXPECT_EQ(m.labelsOutsidePredictions.size(), 1u);  // after the last
	// prediction 1 lies inside the labels' span without its label: a
	// missing label (issue 55); one after the last label: a longer run
	ASSERT_EQ(m.predictionsWithoutLabel.size(), 1u);
	EXPECT_EQ(m.predictionsWithoutLabel[0]->index, 1);
	EXPECT_EQ(m.predictionsOutside, 0);
	const std::vector<ev::MaskFile> longer = {byIndex(0), byIndex(2),
	                                          byIndex(3)};
	const auto l = ev::matchMasks(labels, longer, {}, 0.01);
	EXPECT_TRUE(l.predictionsWithoutLabel.empty());
	EXPECT_EQ(l.predictionsOutside, 1);
	// labels by index, predictions by time: an error
	EXPECT_THROW(ev::matchMasks(labels, {byTime(1.0)}, {}, 0.01),
	             std::runtime_error);
}
