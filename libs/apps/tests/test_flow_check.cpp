// bims-flow-check's logic (flow_check.h): its lines, its summary, a strip
// tile, and a run over the bundled sample.
#include <bims/apps/app.h>
#include <bims/apps/flow_check.h>
#include <bims_test/sample.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <mrpt/system/filesystem.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>

using namespace bims::apps;
using bims::flow::PoseSourceCheck;

namespace
{
using bims::test::kSample;
const std::string kGt = bims::test::kSampleGt + "groundtruth.txt";
using bims::test::kDefaultConfig;

PoseSourceCheck counting()
{
	PoseSourceCheck c;
	c.validPx = 76800;
	for (size_t k = 0; k < c.values.size(); k++) c.values[k] = k + 0.25;
	return c;
}

size_t count(const std::string& s, char c)
{
	return static_cast<size_t>(std::count(s.begin(), s.end(), c));
}
}  // namespace

TEST(FlowCheck, TableAndCsvLinesHoldEveryValue)
{
	const auto c = counting();
	EXPECT_EQ(tableLine(7, 2048, c),
	          "   7 2048 |   0.2   1.2   2.2   3.2 |  4.25  5.25  6.25  7.25 | "
	          " 8.25  9.25 10.25 11.25 |  12.2  13.2  14.2  15.2 | 16.25  17.2 "
	          "| 18.25\n");
	const std::string csv = csvLine(7, 2048, c);
	EXPECT_EQ(csv.rfind("7,2048,76800,0.25,1.25,", 0), 0u) << csv;
	EXPECT_EQ(count(csv, ','), count(csvHeader(), ','));
	EXPECT_EQ(count(tableLine(7, 0, c), '|'), count(tableHeader(), '|'));
}

TEST(FlowCheck, SummaryHasMeanAndMedianOfEveryColumn)
{
	std::vector<std::array<double, PoseSourceCheck::kValues>> rows(3);
	for (size_t i = 0; i < 3; i++) rows[i].fill(0);
	rows[0][0] = 1, rows[1][0] = 2, rows[2][0] = 9;  // mean 4, median 2
	rows[0][18] = 0.5, rows[1][18] = 0.5, rows[2][18] = 0.2;
	const std::string s = summary(rows);
	EXPECT_EQ(s.rfind("# mean over 3 frames:\n"
	                  "diff_%_ego         mean    4.000 median    2.000\n",
	                  0),
	          0u)
	    << s;
	EXPECT_NE(s.find("\nedge_share_used    mean    0.400 median    0.500\n"),
	          std::string::npos)
	    << s;
	EXPECT_EQ(count(s, '\n'), 1 + PoseSourceCheck::kValues);
}

TEST(FlowCheck, StripTileIsTheColourImageWithTheMaskInRed)
{
	mrpt::obs::CObservation3DRangeScan scan;
	const cv::Mat grey(60, 80, CV_8UC1, cv::Scalar(100));
	cv::Mat mask(60, 80, CV_8UC1, cv::Scalar(0));
	mask(cv::Rect(40, 40, 10, 10)).setTo(255);
	// no colour image: the grey one
	cv::Mat t = stripTile(scan, grey, mask, 3);
	ASSERT_EQ(t.type(), CV_8UC3);
	EXPECT_EQ(t.at<cv::Vec3b>(55, 5), cv::Vec3b(100, 100, 100));
	// 0.5 * 100 + 0.5 * (0, 0, 255), as every mask picture
	EXPECT_EQ(t.at<cv::Vec3b>(45, 45), cv::Vec3b(50, 50, 178));
	EXPECT_GT(cv::countNonZero(t.reshape(1) == 255), 0);  // "frame 3"
	// a colour image of the same size is used
	scan.hasIntensityImage = true;
	scan.intensityImage = mrpt::img::CImage(
	    cv::Mat(60, 80, CV_8UC3, cv::Scalar(10, 20, 30)), mrpt::img::DEEP_COPY);
	t = stripTile(scan, grey, mask, 3);
	EXPECT_EQ(t.at<cv::Vec3b>(55, 5), cv::Vec3b(10, 20, 30));
}

TEST(FlowCheck, RunsTheSampleIntoTableCsvSummaryAndStrip)
{
	const std::string d = bims::test::freshTmpDir("bims_test_check", "run");
	FlowCheckOptions o;
	o.config = kDefaultConfig;
	o.rawlog = kSample;
	o.gt = kGt;
	o.frames = "0:8";
	o.csv = d + "/frames.csv";
	o.strip = d + "/strip.png";
	o.stripFrames = "3,6";
	o.progress = false;
	testing::internal::CaptureStdout();
	EXPECT_EQ(runFlowCheck(o), 0);
	const std::string out = testing::internal::GetCapturedStdout();
	EXPECT_EQ(out.rfind(tableHeader(), 0), 0u) << out;
	EXPECT_NE(out.find("# mean over 8 frames:\n"), std::string::npos) << out;
	EXPECT_NE(out.find("run: mean moving-pixel fraction "), std::string::npos);
	EXPECT_NE(out.find("(flow-only), "), std::string::npos) << out;
	EXPECT_NE(out.find("strip: " + *o.strip + " (2 frames)\n"),
	          std::string::npos);
	std::ifstream f(*o.csv);
	std::string line;
	size_t n = 0;
	while (std::getline(f, line)) ++n;
	EXPECT_EQ(n, 9u);  // header + frames 1..8
	const cv::Mat strip = cv::imread(*o.strip);
	EXPECT_EQ(strip.cols, 2 * 160);  // two 320x240 frames at half size
	EXPECT_EQ(strip.rows, 120);
}

TEST(FlowCheck, BadOptionsAreUsageErrorsBeforeAnyRun)
{
	FlowCheckOptions o;
	o.config = kDefaultConfig;
	o.rawlog = kSample;
	o.gt = kGt;
	o.progress = false;
	auto noFrames = o;
	noFrames.strip = "x.png";
	EXPECT_THROW(runFlowCheck(noFrames), bims::UsageError);
	auto variant = o;
	variant.variant = "nope";
	EXPECT_THROW(runFlowCheck(variant), bims::UsageError);
	auto same = o;
	same.csv = kGt;
	EXPECT_THROW(runFlowCheck(same), bims::UsageError);
	EXPECT_FALSE(mrpt::system::fileExists("x.png"));
}
