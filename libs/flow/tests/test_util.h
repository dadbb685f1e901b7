// Shared synthetic inputs for the flow tests.
#pragma once

#include <mrpt/img/TCamera.h>
#include <opencv2/imgproc.hpp>

#include <random>

namespace bims::flow::test
{
inline mrpt::img::TCamera vgaCamera(int w = 640, int h = 480)
{
	mrpt::img::TCamera c;
	c.ncols = w;
	c.nrows = h;
	c.setIntrinsicParamsFromValues(525.0 * w / 640, 525.0 * w / 640,
	                               w / 2.0 - 0.5, h / 2.0 - 0.5);
	return c;
}

/** Smoothed random texture with corners at several scales (CV_8UC1). */
inline cv::Mat texture(int w, int h, unsigned seed)
{
	std::mt19937 rng(seed);
	std::uniform_int_distribution<int> d(0, 255);
	cv::Mat small(h / 8 + 2, w / 8 + 2, CV_8UC1), fine(h, w, CV_8UC1);
	for (int i = 0; i < small.rows * small.cols; i++) small.data[i] = d(rng);
	for (int i = 0; i < fine.rows * fine.cols; i++) fine.data[i] = d(rng);
	cv::Mat big;
	cv::resize(small, big, cv::Size(w, h), 0, 0, cv::INTER_CUBIC);
	cv::GaussianBlur(fine, fine, cv::Size(0, 0), 1.5);
	cv::Mat out;
	cv::addWeighted(big, 0.7, fine, 0.6, -40, out);
	return out;
}

/** Shifts an image by (dx, dy): out(x) = in(x - d). */
inline cv::Mat shifted(const cv::Mat& in, double dx, double dy)
{
	cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
	cv::Mat out;
	cv::warpAffine(in, out, M, in.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
	return out;
}
}  // namespace bims::flow::test
