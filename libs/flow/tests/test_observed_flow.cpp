#include <bims/flow/observed_flow.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "test_util.h"

using namespace bims::flow;

namespace
{
/** Median end-point error against a constant flow, over the inner image. */
double medianError(const cv::Mat& flow, double fx, double fy)
{
	std::vector<double> e;
	for (int v = 20; v < flow.rows - 20; v += 2)
		for (int u = 20; u < flow.cols - 20; u += 2)
		{
			const auto f = flow.at<cv::Vec2f>(v, u);
			e.push_back(std::hypot(f[0] - fx, f[1] - fy));
		}
	std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
	return e[e.size() / 2];
}
}  // namespace

TEST(ObservedFlow, RecoversASubpixelShiftWithEveryMethod)
{
	const cv::Mat prev = test::texture(320, 240, 7);
	const cv::Mat cur = test::shifted(prev, 2.3, -1.7);  // content moved by +d
	struct Case
	{
		std::string method;
		int downscale;
		double tol;
	};
	for (const auto& c : {Case{"dis", 1, 0.15}, Case{"farneback", 1, 0.15},
	                      Case{"dis", 2, 0.35}})
	{
		FlowParams p;
		p.method = c.method;
		p.downscale = c.downscale;
		ObservedFlow of(p);
		const cv::Mat flow = of.compute(prev, cur);
		ASSERT_EQ(flow.type(), CV_32FC2);
		ASSERT_EQ(flow.size(), cur.size());
		// backward flow: u_prev - u_cur = -d
		EXPECT_LT(medianError(flow, -2.3, 1.7), c.tol)
		    << c.method << " /" << c.downscale;
	}
}

TEST(ObservedFlow, RejectsMismatchedImages)
{
	ObservedFlow of;
	EXPECT_THROW(of.compute(cv::Mat(10, 10, CV_8UC1), cv::Mat(10, 12, CV_8UC1)),
	             std::invalid_argument);
	EXPECT_THROW(of.compute(cv::Mat(), cv::Mat()), std::invalid_argument);
	EXPECT_THROW(of.compute(cv::Mat(10, 10, CV_8UC3), cv::Mat(10, 10, CV_8UC3)),
	             std::invalid_argument);
}
