// The bar chart of bims-sweep's results.png (eval::plotGroupedBars).
#include <bims/eval/plots.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace ev = bims::eval;

namespace
{
/** Pixels of exactly \a bgr in the columns [x0, x1) of \a img, below the
 * title and the legend (a row of swatches above y = 70). */
int countColour(const cv::Mat& img, const cv::Vec3b& bgr, int x0, int x1)
{
	int n = 0;
	for (int y = 70; y < img.rows; y++)
		for (int x = x0; x < x1; x++) n += img.at<cv::Vec3b>(y, x) == bgr;
	return n;
}
const cv::Vec3b kFirstSeries(180, 119, 31), kSecondSeries(14, 127, 255);
}  // namespace

TEST(GroupedBars, BarsAreProportionalToTheValuesInTheSeriesColours)
{
	ev::GroupedBars c;
	c.title = "fps per run";
	c.yLabel = "frames/s";
	c.xLabel = "overrides";
	c.groups = {"a=1", "a=2"};
	c.series = {"x.rawlog", "y.rawlog"};
	c.values = {{10, 5}, {20, 15}};
	const cv::Mat img = ev::plotGroupedBars(c);
	ASSERT_EQ(img.type(), CV_8UC3);
	EXPECT_EQ(img.cols, 1024);
	EXPECT_EQ(img.rows, 640);
	// the groups share the plot's width: the first in the left half
	const int mid = 96 + (1024 - 96 - 30) / 2;
	const int a1 = countColour(img, kFirstSeries, 96, mid);
	const int a2 = countColour(img, kFirstSeries, mid, img.cols);
	const int b1 = countColour(img, kSecondSeries, 96, mid);
	const int b2 = countColour(img, kSecondSeries, mid, img.cols);
	ASSERT_GT(a1, 100);
	// bars of one width: areas in the ratio of the values (within a few
	// rows of rounding)
	EXPECT_NEAR(static_cast<double>(a2) / a1, 2.0, 0.06);
	EXPECT_NEAR(static_cast<double>(b2) / b1, 3.0, 0.12);
}

TEST(GroupedBars, ManyGroupsWidenTheChartAndAMissingValueIsNoBar)
{
	ev::GroupedBars c;
	c.title = "t";
	const double nan = std::numeric_limits<double>::quiet_NaN();
	for (int g = 0; g < 30; g++)
	{
		c.groups.push_back("voxel_size=0.0" + std::to_string(g % 10) +
		                   "\nvariant=fused-raycast");
		c.values.push_back({g == 0 ? nan : 1.0 + g});
	}
	c.series = {"s"};
	const cv::Mat img = ev::plotGroupedBars(c);
	EXPECT_GT(img.cols, 1024);
	EXPECT_EQ(img.rows, 640);
	// group 0 (left of group 1's label centre) holds no bar, but the red x
	const int g0End = 96 + (img.cols - 96 - 30) / 30;
	EXPECT_EQ(countColour(img, kFirstSeries, 96 + 2, g0End - 2), 0);
	EXPECT_GT(countColour(img, kFirstSeries, g0End + 2, img.cols), 0);
}

TEST(GroupedBars, AScoresAxisEndsAtItsTop)
{
	// F1 0.5: without a top the axis ends a step above the value (0.6),
	// with yMax = 1 at 1: the same bar is 0.6 times as tall
	ev::GroupedBars c;
	c.title = "F1 per run";
	c.groups = {"a=1"};
	c.series = {"x"};
	c.values = {{0.5}};
	const int free =
	    countColour(ev::plotGroupedBars(c), kFirstSeries, 96, 1024);
	c.yMax = 1.0;
	const int scored =
	    countColour(ev::plotGroupedBars(c), kFirstSeries, 96, 1024);
	ASSERT_GT(free, 100);
	EXPECT_NEAR(static_cast<double>(scored) / free, 0.6, 0.03);
	// a value above the top keeps the axis over it
	c.values = {{1.4}};
	EXPECT_GT(countColour(ev::plotGroupedBars(c), kFirstSeries, 96, 1024), 0);
}

TEST(GroupedBars, ValuesNotOnePerGroupAndSeriesAreRefused)
{
	ev::GroupedBars c;
	c.groups = {"a", "b"};
	c.series = {"s"};
	c.values = {{1.0}};
	EXPECT_THROW(ev::plotGroupedBars(c), std::invalid_argument);
	c.values = {{1.0}, {1.0, 2.0}};
	EXPECT_THROW(ev::plotGroupedBars(c), std::invalid_argument);
}
