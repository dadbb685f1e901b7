// bims-flow-labels' run (pair_labels.h): the camera and pose of the command
// line, the labels of one pair, the overlay, the files written.
#include <bims/common/app.h>
#include <bims/flow/pair_labels.h>
#include <bims_test/png_bomb.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

namespace
{
/** A textured BGR image: smooth blobs that dense flow can follow. */
cv::Mat texture(int cols, int rows, int shift)
{
	cv::Mat m(rows, cols, CV_8UC3);
	for (int v = 0; v < rows; v++)
		for (int u = 0; u < cols; u++)
		{
			const double x = u - shift;
			const auto g =
			    static_cast<uint8_t>(128 + 60 * std::sin(x * 0.21) +
			                         60 * std::cos(v * 0.17 + x * 0.05));
			m.at<cv::Vec3b>(v, u) = cv::Vec3b(g, g, g);
		}
	return m;
}

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

TEST(PairLabels, ThePoseIsSixNumbersMetresAndDegrees)
{
	const auto p = bims::flow::parsePoseXyzYpr("0.5 -1 2 90 0 -30");
	EXPECT_DOUBLE_EQ(p.x(), 0.5);
	EXPECT_DOUBLE_EQ(p.y(), -1.0);
	EXPECT_DOUBLE_EQ(p.z(), 2.0);
	EXPECT_NEAR(p.yaw(), M_PI / 2, 1e-12);
	EXPECT_NEAR(p.roll(), -M_PI / 6, 1e-12);
	try
	{
		bims::flow::parsePoseXyzYpr("1 2");
		ADD_FAILURE() << "no error for two numbers";
	}
	catch (const bims::UsageError& e)
	{
		EXPECT_STREQ(e.what(), "--pose needs 6 numbers 'x y z yaw pitch roll'");
	}
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
		return bims::flow::labelPair(texture(160, 120, 0),
		                             texture(160, 120, shift), depth, 5000, cam,
		                             {}, params);
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

TEST(PairLabels, TheRunWritesFourPicturesAndNamesBadInputs)
{
	const auto d = bims::test::freshTmpDir("bims_test_flow", "pair_labels");
	cv::imwrite(d + "/a.png", texture(160, 120, 0));
	cv::imwrite(d + "/b.png", texture(160, 120, 2));
	cv::imwrite(d + "/d.png", cv::Mat(120, 160, CV_16UC1, cv::Scalar(9000)));
	std::ofstream(d + "/c.ini") << "[flow]\nvisible_change_grey = 0\n";
	bims::flow::FlowLabelsOptions o;
	o.rgb0 = d + "/a.png";
	o.rgb1 = d + "/b.png";
	o.depth1 = d + "/d.png";
	o.out = d + "/out";
	o.config = d + "/c.ini";
	EXPECT_EQ(bims::flow::runFlowLabels(o), 0);
	for (const char* f : {"observed_flow.png", "expected_flow.png",
	                      "labels.png", "overlay.png"})
		EXPECT_EQ(cv::imread(o.out + "/" + f).size(), cv::Size(160, 120)) << f;

	auto errorOf = [](const bims::flow::FlowLabelsOptions& bad) -> std::string
	{
		try
		{
			bims::flow::runFlowLabels(bad);
		}
		catch (const std::exception& e)
		{
			return e.what();
		}
		return "";
	};
	auto bad = o;
	bad.depth1 = o.rgb1;
	EXPECT_EQ(errorOf(bad),
	          o.rgb1 + ": depth must be a 16-bit single-channel PNG");
	bad = o;
	cv::imwrite(d + "/small.png", texture(80, 60, 0));
	bad.rgb0 = d + "/small.png";
	EXPECT_EQ(errorOf(bad), "images differ in size: " + bad.rgb0 + ", " +
	                            o.rgb1 + ", " + o.depth1);
	bad = o;
	bad.config = d + "/none.ini";
	EXPECT_EQ(errorOf(bad), d + "/none.ini: no such config file");
	bad = o;
	bad.rgb1 = d + "/none.png";
	EXPECT_EQ(errorOf(bad), d + "/none.png: cannot read image: no such file");
	// a decompression bomb: refused from its header (bims/common/image_file.h)
	bad = o;
	bims::test::writePngBomb(d + "/bomb.png");
	bad.rgb0 = d + "/bomb.png";
	EXPECT_NE(errorOf(bad).find("declares 30000 x 30000 pixels"),
	          std::string::npos)
	    << errorOf(bad);
}
