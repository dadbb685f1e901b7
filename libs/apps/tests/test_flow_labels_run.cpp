// bims-flow-labels' run (flow_labels_run.h): the pose of its command line,
// the files written, bad inputs named.
#include <bims/apps/app.h>
#include <bims/apps/flow_labels_run.h>
#include <bims_test/flow_texture.h>
#include <bims_test/png_bomb.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

namespace
{
using bims::test::flowTexture;
}  // namespace

TEST(FlowLabelsRun, ThePoseIsSixNumbersMetresAndDegrees)
{
	const auto p = bims::apps::parsePoseXyzYpr("0.5 -1 2 90 0 -30");
	EXPECT_DOUBLE_EQ(p.x(), 0.5);
	EXPECT_DOUBLE_EQ(p.y(), -1.0);
	EXPECT_DOUBLE_EQ(p.z(), 2.0);
	EXPECT_NEAR(p.yaw(), M_PI / 2, 1e-12);
	EXPECT_NEAR(p.roll(), -M_PI / 6, 1e-12);
	try
	{
		bims::apps::parsePoseXyzYpr("1 2");
		ADD_FAILURE() << "no error for two numbers";
	}
	catch (const bims::UsageError& e)
	{
		EXPECT_STREQ(e.what(), "--pose needs 6 numbers 'x y z yaw pitch roll'");
	}
}

TEST(FlowLabelsRun, TheRunWritesFourPicturesAndNamesBadInputs)
{
	const auto d = bims::test::freshTmpDir("bims_test_flow", "pair_labels");
	cv::imwrite(d + "/a.png", flowTexture(160, 120, 0));
	cv::imwrite(d + "/b.png", flowTexture(160, 120, 2));
	cv::imwrite(d + "/d.png", cv::Mat(120, 160, CV_16UC1, cv::Scalar(9000)));
	std::ofstream(d + "/c.ini") << "[flow]\nvisible_change_grey = 0\n";
	bims::apps::FlowLabelsOptions o;
	o.rgb0 = d + "/a.png";
	o.rgb1 = d + "/b.png";
	o.depth1 = d + "/d.png";
	o.out = d + "/out";
	o.config = d + "/c.ini";
	EXPECT_EQ(bims::apps::runFlowLabels(o), 0);
	for (const char* f : {"observed_flow.png", "expected_flow.png",
	                      "labels.png", "overlay.png"})
		EXPECT_EQ(cv::imread(o.out + "/" + f).size(), cv::Size(160, 120)) << f;

	auto errorOf = [](const bims::apps::FlowLabelsOptions& bad) -> std::string
	{
		try
		{
			bims::apps::runFlowLabels(bad);
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
	cv::imwrite(d + "/small.png", flowTexture(80, 60, 0));
	bad.rgb0 = d + "/small.png";
	EXPECT_EQ(errorOf(bad), "images differ in size: " + bad.rgb0 + ", " +
	                            o.rgb1 + ", " + o.depth1);
	bad = o;
	bad.config = d + "/none.ini";
	EXPECT_EQ(errorOf(bad), d + "/none.ini: no such config file");
	bad = o;
	bad.rgb1 = d + "/none.png";
	EXPECT_EQ(errorOf(bad), d + "/none.png: cannot read image: no such file");
	// a decompression bomb: refused from its header (bims/io/image_file.h)
	bad = o;
	bims::test::writePngBomb(d + "/bomb.png");
	bad.rgb0 = d + "/bomb.png";
	EXPECT_NE(errorOf(bad).find("declares 30000 x 30000 pixels"),
	          std::string::npos)
	    << errorOf(bad);
	// the limits are [input]'s of the config (issue 39)
	bad = o;
	bad.config = d + "/small.ini";
	std::ofstream(*bad.config) << "[input]\nimage_max_side = 100\n";
	EXPECT_NE(errorOf(bad).find(o.rgb0 +
	                            ": cannot read image: declares 160 x 120 "
	                            "pixels in its PNG header, beyond the 100 per "
	                            "side"),
	          std::string::npos)
	    << errorOf(bad);
}
