// Mask metrics on a hand-computed 4x4 example.
#include <bims/eval/mask_metrics.h>
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>

namespace ev = bims::eval;

namespace
{
cv::Mat mat4(const uint8_t v[16])
{
	return cv::Mat(4, 4, CV_8UC1, const_cast<uint8_t*>(v)).clone();
}
// gt:  X X . .    pred: X . . .
//      X X . .          X X X .
//      . . . .          . . . .
//      . . . X          . . . .
const uint8_t kGt[16] = {255, 255, 0, 0, 255, 255, 0, 0,
                         0,   0,   0, 0, 0,   0,   0, 255};
const uint8_t kPred[16] = {255, 0, 0, 0, 255, 255, 255, 0,
                           0,   0, 0, 0, 0,   0,   0,   0};
}  // namespace

TEST(MaskMetrics, HandComputedAllPixelsValid)
{
	// TP (0,0),(1,0),(1,1) = 3; FP (1,2) = 1; FN (0,1),(3,3) = 2; TN 10.
	const auto m = ev::MaskMetrics::compute(mat4(kGt), mat4(kPred));
	EXPECT_EQ(m.tp, 3u);
	EXPECT_EQ(m.fp, 1u);
	EXPECT_EQ(m.fn, 2u);
	EXPECT_EQ(m.tn, 10u);
	EXPECT_DOUBLE_EQ(m.precision(), 0.75);
	EXPECT_DOUBLE_EQ(m.recall(), 0.6);
	EXPECT_DOUBLE_EQ(m.f1(), 6.0 / 9.0);
	EXPECT_DOUBLE_EQ(m.iou(), 0.5);
	EXPECT_EQ(m.scoresLine(),
	          "precision 0.7500 recall 0.6000 F1 0.6667 IoU 0.5000");
}

TEST(MaskMetrics, InvalidDepthPixelsAreSkipped)
{
	// Pixel (3,3) (an FN) has no depth: FN = 1, recall 3/4, IoU 3/5.
	cv::Mat valid(4, 4, CV_8UC1, cv::Scalar(1));
	valid.at<uint8_t>(3, 3) = 0;
	ev::MaskMetrics m;
	m.accumulate(mat4(kGt), mat4(kPred), valid);
	EXPECT_EQ(m.fn, 1u);
	EXPECT_EQ(m.invalid, 1u);
	EXPECT_DOUBLE_EQ(m.recall(), 0.75);
	EXPECT_DOUBLE_EQ(m.f1(), 0.75);
	EXPECT_DOUBLE_EQ(m.iou(), 0.6);
	// Accumulating a second frame sums the counts (not the scores).
	m.accumulate(mat4(kGt), mat4(kGt), valid);  // 4 TP more
	EXPECT_EQ(m.tp, 7u);
	EXPECT_DOUBLE_EQ(m.precision(), 7.0 / 8.0);
}

TEST(MaskMetrics, UndefinedScoresAreNan)
{
	const cv::Mat z = cv::Mat::zeros(4, 4, CV_8UC1);
	const auto m = ev::MaskMetrics::compute(z, z);
	EXPECT_EQ(m.tn, 16u);
	EXPECT_TRUE(std::isnan(m.precision()));
	EXPECT_TRUE(std::isnan(m.recall()));
	EXPECT_EQ(m.scoresLine(), "precision nan recall nan F1 nan IoU nan");
	EXPECT_NE(bims::jsonText(m.toJson()).find("\"precision\": null"),
	          std::string::npos);
}

TEST(MaskMetrics, MismatchedSizesAndTypesAreErrors)
{
	const cv::Mat a = cv::Mat::zeros(4, 4, CV_8UC1),
	              b = cv::Mat::zeros(4, 5, CV_8UC1);
	EXPECT_THROW(ev::MaskMetrics::compute(a, b), std::invalid_argument);
	EXPECT_THROW(ev::MaskMetrics::compute(a, cv::Mat::zeros(4, 4, CV_16UC1)),
	             std::invalid_argument);
	EXPECT_THROW(ev::MaskMetrics::compute(a, a, b), std::invalid_argument);
}

TEST(MaskMetrics, LoadMaskNamesTheFile)
{
	try
	{
		ev::loadMask("/nonexistent/000001.png");
		FAIL();
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("000001.png"), std::string::npos);
	}
}

TEST(MaskMetrics, OverlayColours)
{
	// 100x100 masks with a TP, an FP and an FN block away from the caption
	// (top 22 rows) and the legend (bottom rows); one pixel without depth.
	cv::Mat g(100, 100, CV_8UC1, cv::Scalar(0)), p = g.clone();
	cv::Mat valid(100, 100, CV_8UC1, cv::Scalar(255));
	g(cv::Rect(40, 40, 10, 10)) = 255;
	p(cv::Rect(40, 40, 10, 10)) = 255;  // TP
	p(cv::Rect(60, 40, 10, 10)) = 255;  // FP
	g(cv::Rect(40, 60, 10, 10)) = 255;  // FN
	valid.at<uint8_t>(70, 70) = 0;
	const cv::Mat ov = ev::maskOverlay(g, p, valid, cv::Mat(), "caption");
	ASSERT_EQ(ov.type(), CV_8UC3);
	EXPECT_EQ(ov.at<cv::Vec3b>(45, 45), cv::Vec3b(0, 200, 0));
	EXPECT_EQ(ov.at<cv::Vec3b>(45, 65), cv::Vec3b(0, 0, 230));
	EXPECT_EQ(ov.at<cv::Vec3b>(65, 45), cv::Vec3b(230, 80, 0));
	EXPECT_EQ(ov.at<cv::Vec3b>(70, 70), cv::Vec3b(40, 40, 40));
	EXPECT_EQ(ov.at<cv::Vec3b>(50, 90), cv::Vec3b(0, 0, 0));
}

TEST(VoxelMaskMetrics, EachCellCountsOnceHoweverManyPixelsSeeIt)
{
	// 64x64 px, f = 64 px: a near object (0.5 m, left 32 columns) and a far
	// one (4 m, right 32 columns), both moving in the ground truth; the
	// prediction finds only the far one. At 5 cm a far pixel (6.25 cm) is a
	// cell of its own, near pixels share cells (0.78 cm each).
	const int W = 64, H = 64;
	cv::Mat depth(H, W, CV_32FC1), gt(H, W, CV_8UC1, cv::Scalar(255)),
	    pred = cv::Mat::zeros(H, W, CV_8UC1);
	depth.colRange(0, 32).setTo(0.5f);
	depth.colRange(32, 64).setTo(4.0f);
	pred.colRange(32, 64).setTo(255);
	const auto px = bims::eval::MaskMetrics::compute(gt, pred);
	EXPECT_DOUBLE_EQ(px.recall(), 0.5);
	const auto vx =
	    bims::eval::voxelMaskMetrics(gt, pred, depth, 64, 64, 32, 32, 0.05);
	EXPECT_EQ(vx.fp, 0u);
	EXPECT_EQ(vx.tp, 32u * 64u);  // one far cell per pixel
	EXPECT_GT(vx.fn, 0u);
	EXPECT_GT(vx.recall(), 0.9);
	// Identical masks score 1; holes in depth are counted as invalid.
	depth.at<float>(0, 0) = 0;
	depth.at<float>(1, 1) = std::nanf("");
	const auto same =
	    bims::eval::voxelMaskMetrics(gt, gt, depth, 64, 64, 32, 32, 0.05);
	EXPECT_DOUBLE_EQ(same.f1(), 1.0);
	EXPECT_EQ(same.invalid, 2u);
	EXPECT_THROW(bims::eval::voxelMaskMetrics(gt, gt, depth, 64, 64, 32, 32, 0),
	             std::invalid_argument);
	EXPECT_THROW(bims::eval::voxelMaskMetrics(gt, gt.colRange(0, 8).clone(),
	                                          depth, 64, 64, 32, 32, 0.05),
	             std::invalid_argument);
}
