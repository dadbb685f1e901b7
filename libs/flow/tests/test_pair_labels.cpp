// The labels of one image pair (pair_labels.h): the camera, the labels of a
// still and a moved pair, the overlay.
#include <bims/flow/pair_labels.h>
#include <bims_test/flow_texture.h>
#include <bims_test/png_bomb.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

namespace
{
using bims::test::flowTexture;

bims::flow::FlowParams noVisibleChange()
{
	bims::flow::FlowParams p;
	p.visible_change_grey = 0;
	return p;
}
}  // namespace

TEST(PairLabels, TheCameraDefaultsTo525AtVgaScaledAndTheCentre)
{
	const auto d = bims::flow::pairCamera(320, 240, 0, -1, -1, -1);
	EXPECT_DOUBLE_EQ(d.fx(), 262.5);
	EXPECT_DOUBLE_EQ(d.fy(), 262.5);
	EXPECT_DOUBLE_EQ(d.cx(), 160.0);
	EXPECT_DOUBLE_EQ(d.cy(), 120.0);
	EXPECT_EQ(d.ncols, 320u);
	EXPECT_EQ(d.nrows, 240u);
	const auto g = bims::flow::pairCamera(320, 240, 300, 301, 0, 7);
	EXPECT_DOUBLE_EQ(g.fx(), 300.0);
	EXPECT_DOUBLE_EQ(g.fy(), 301.0);
	EXPECT_DOUBLE_EQ(g.cx(), 0.0);
	EXPECT_DOUBLE_EQ(g.cy(), 7.0);
}

namespace
{
/** The labels of a still pair and of a pair whose image moved 4 px while
 * the camera (identity pose) did not, a wall 2 m away. */
std::pair<bims::flow::PairLabels, bims::flow::PairLabels> stillAndMoved(
    const bims::flow::FlowParams& params)
{
	const auto cam = bims::flow::pairCamera(160, 120, 0, 0, -1, -1);
	const cv::Mat depth(120, 160, CV_16UC1, cv::Scalar(10000));  // 2 m
	auto pair = [&](int shift)
	{
		return bims::flow::labelPair(flowTexture(160, 120, 0),
		                             flowTexture(160, 120, shift), depth, 5000,
		                             cam, {}, params);
	};
	return {pair(0), pair(4)};
}
}  // namespace

TEST(PairLabels, AStillPairIsConsistentAMovedImageIsNot)
{
	const auto [still, moved] = stillAndMoved(noVisibleChange());
	EXPECT_EQ(still.labels.size(), cv::Size(160, 120));
	EXPECT_GT(still.stats.notDiff, 10000u);
	EXPECT_EQ(still.stats.diff, 0u);
	EXPECT_GT(moved.stats.diff, 10000u);
}

TEST(PairLabels, TheDefaultFlowParametersRunWithTheImagesStructureTensor)
{
	// [flow]'s defaults gate a Diff by the visible change of the grey image
	// (visible_change_grey > 0), which needs the current image's structure
	// tensor: the pair is labelled with it (it was an error before)
	const bims::flow::FlowParams params;
	ASSERT_GT(params.visible_change_grey, 0);
	const auto [still, moved] = stillAndMoved(params);
	EXPECT_GT(still.stats.notDiff, 10000u);
	EXPECT_EQ(still.stats.diff, 0u);
	EXPECT_GT(moved.stats.diff, 5000u);
}

TEST(PairLabels, TheOverlayTurnsDiffPixelsHalfRed)
{
	const cv::Mat rgb(2, 2, CV_8UC3, cv::Scalar(100, 60, 20));
	cv::Mat labels(2, 2, CV_8SC1, cv::Scalar(bims::flow::kNotDiff));
	labels.at<int8_t>(1, 0) = bims::flow::kDiff;
	const cv::Mat o = bims::flow::diffOverlay(rgb, labels);
	EXPECT_EQ(o.at<cv::Vec3b>(1, 0), cv::Vec3b(50, 30, 137));
	EXPECT_EQ(o.at<cv::Vec3b>(0, 0), cv::Vec3b(100, 60, 20));
	EXPECT_EQ(rgb.at<cv::Vec3b>(1, 0), cv::Vec3b(100, 60, 20));
}
