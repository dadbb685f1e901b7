#include <bims/flow/expected_flow.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "test_util.h"

using namespace bims::flow;
using mrpt::poses::CPose3D;

namespace
{
cv::Mat randomDepth(int w, int h, unsigned seed)
{
	std::mt19937 rng(seed);
	std::uniform_real_distribution<float> d(0.5f, 5.0f);
	cv::Mat z(h, w, CV_32FC1);
	for (int v = 0; v < h; v++)
		for (int u = 0; u < w; u++) z.at<float>(v, u) = d(rng);
	return z;
}

double maxDiff(const cv::Mat& a, const cv::Mat& b)
{
	double m = 0;
	for (int v = 0; v < a.rows; v++)
		for (int u = 0; u < a.cols; u++)
		{
			const auto x = a.at<cv::Vec2f>(v, u), y = b.at<cv::Vec2f>(v, u);
			if (!std::isfinite(x[0]) || !std::isfinite(y[0])) continue;
			m = std::max(
			    m, static_cast<double>(std::hypot(x[0] - y[0], x[1] - y[1])));
		}
	return m;
}
}  // namespace

TEST(ExpectedFlow, PureRotationEqualsHomographyFlow)
{
	const auto cam = test::vgaCamera(320, 240);
	const cv::Mat z = randomDepth(320, 240, 1);
	const CPose3D R(0, 0, 0, mrpt::DEG2RAD(2.0), mrpt::DEG2RAD(-1.0),
	                mrpt::DEG2RAD(1.5));
	const cv::Mat e = expectedFlowExact(z, cam, R);
	const cv::Mat h = homographyFlow(cam, R);
	EXPECT_LT(maxDiff(e, h), 1e-3);
	// and the flow is not trivially zero
	EXPECT_GT(std::abs(h.at<cv::Vec2f>(120, 160)[0]), 3.0f);
}

TEST(ExpectedFlow, ExactFlowMatchesIndependentProjection)
{
	const auto cam = test::vgaCamera();
	const cv::Mat z = randomDepth(640, 480, 2);
	const CPose3D T_CprevC(0.03, -0.02, 0.05, 0.02, -0.01, 0.03);
	const cv::Mat e = expectedFlowExact(z, cam, T_CprevC);
	std::mt19937 rng(3);
	for (int k = 0; k < 200; k++)
	{
		const int u = rng() % 640, v = rng() % 480;
		const double d = z.at<float>(v, u);
		// independent path: MRPT pose composition and the pinhole formula
		const mrpt::math::TPoint3D p((u - cam.cx()) * d / cam.fx(),
		                             (v - cam.cy()) * d / cam.fy(), d);
		const auto q = T_CprevC.composePoint(p);
		const double up = cam.fx() * q.x / q.z + cam.cx();
		const double vp = cam.fy() * q.y / q.z + cam.cy();
		EXPECT_NEAR(e.at<cv::Vec2f>(v, u)[0], up - u, 1e-3);
		EXPECT_NEAR(e.at<cv::Vec2f>(v, u)[1], vp - v, 1e-3);
	}
}

TEST(ExpectedFlow, LinearFormIsFirstOrderAccurate)
{
	const auto cam = test::vgaCamera(320, 240);
	const cv::Mat z = randomDepth(320, 240, 4);
	double prevErr = 0;
	for (double s : {1.0, 0.1, 0.01})
	{
		const CPose3D T(0.04 * s, 0.02 * s, -0.03 * s, 0.03 * s, 0.02 * s,
		                -0.025 * s);
		const double err = maxDiff(expectedFlowExact(z, cam, T),
		                           expectedFlowLinear(z, cam, T));
		if (s < 1.0)
		{
			EXPECT_LT(err, prevErr * 0.1 * 0.1 * 2.0)
			    << "not second order at s=" << s;
		}
		prevErr = err;
	}
	EXPECT_LT(prevErr, 1e-3);
}

TEST(ExpectedFlow, ProjectionJacobianMatchesCentralDifferences)
{
	const auto cam = test::vgaCamera();
	const mrpt::math::TPoint3D p(0.4, -0.3, 2.1);
	double J[6];
	projectionJacobian(cam, p, J);
	const double h = 1e-6;
	for (int k = 0; k < 3; k++)
	{
		mrpt::math::TPoint3D a = p, b = p;
		a[k] += h;
		b[k] -= h;
		const auto pa = project(cam, a), pb = project(cam, b);
		EXPECT_NEAR(J[k], (pa.x - pb.x) / (2 * h), 1e-4);
		EXPECT_NEAR(J[3 + k], (pa.y - pb.y) / (2 * h), 1e-4);
	}
}

TEST(ExpectedFlow, NoDepthGivesNoFlow)
{
	const auto cam = test::vgaCamera(64, 48);
	cv::Mat z(48, 64, CV_32FC1, cv::Scalar(2.0f));
	z.at<float>(10, 10) = 0.0f;
	z.at<float>(11, 11) = std::numeric_limits<float>::quiet_NaN();
	z.at<float>(12, 12) = std::numeric_limits<float>::infinity();
	z.at<float>(13, 13) = -1.0f;
	z.at<float>(14, 14) = 4.0f;
	const cv::Mat e = expectedFlowExact(z, cam, CPose3D(0.1, 0, 0, 0, 0, 0));
	for (int k : {10, 11, 12, 13})
	{
		EXPECT_TRUE(std::isnan(e.at<cv::Vec2f>(k, k)[0])) << k;
		EXPECT_TRUE(std::isnan(e.at<cv::Vec2f>(k, k)[1])) << k;
	}
	EXPECT_NEAR(e.at<cv::Vec2f>(20, 20)[0], cam.fx() * 0.1 / 2.0, 1e-3);
	EXPECT_NEAR(e.at<cv::Vec2f>(20, 20)[1], 0.0, 1e-6);
	// behind the previous camera (z = 2 m, 3 m back): no flow; 4 m: flow
	const cv::Mat b = expectedFlowExact(z, cam, CPose3D(0, 0, -3, 0, 0, 0));
	EXPECT_TRUE(std::isnan(b.at<cv::Vec2f>(20, 20)[0]));
	EXPECT_TRUE(std::isnan(b.at<cv::Vec2f>(20, 20)[1]));
	EXPECT_TRUE(std::isfinite(b.at<cv::Vec2f>(14, 14)[0]));
	EXPECT_THROW(expectedFlowExact(cv::Mat(10, 10, CV_32FC1), cam, CPose3D()),
	             std::invalid_argument);
}
