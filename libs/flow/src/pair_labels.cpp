#include <bims/common/clock.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/observed_flow.h>
#include <bims/flow/pair_labels.h>

#include <chrono>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace bims::flow
{
mrpt::img::TCamera pairCamera(int cols, int rows, double fx, double fy,
                              double cx, double cy)
{
	mrpt::img::TCamera cam;
	cam.ncols = cols;
	cam.nrows = rows;
	const double f = 525.0 * cols / 640.0;
	cam.setIntrinsicParamsFromValues(fx > 0 ? fx : f, fy > 0 ? fy : f,
	                                 cx >= 0 ? cx : cols / 2.0,
	                                 cy >= 0 ? cy : rows / 2.0);
	return cam;
}

PairLabels labelPair(const cv::Mat& rgb0, const cv::Mat& rgb1,
                     const cv::Mat& depth16, double depthScale,
                     const mrpt::img::TCamera& cam,
                     const mrpt::poses::CPose3D& T_CprevC,
                     const FlowParams& params)
{
	cv::Mat g0, g1, depth;
	cv::cvtColor(rgb0, g0, cv::COLOR_BGR2GRAY);
	cv::cvtColor(rgb1, g1, cv::COLOR_BGR2GRAY);
	depth16.convertTo(depth, CV_32FC1, 1.0 / depthScale);

	PairLabels r;
	ObservedFlow of(params);
	auto t0 = std::chrono::steady_clock::now();
	r.observed = of.compute(g0, g1);
	r.msObserved = msSince(t0);
	t0 = std::chrono::steady_clock::now();
	r.expected = expectedFlow(params.expected, depth, cam, T_CprevC);
	r.msExpected = msSince(t0);
	t0 = std::chrono::steady_clock::now();
	// the current image's structure tensor, computed with the flow when
	// [flow] asks for it (visible_change_grey > 0: the default)
	const cv::Mat& tensor = of.tensor();
	r.labels =
	    labelConsistency(r.observed, r.expected, depth, cam, T_CprevC, params,
	                     &r.stats, tensor.empty() ? nullptr : &tensor);
	r.msLabels = msSince(t0);
	return r;
}

cv::Mat diffOverlay(const cv::Mat& rgb, const cv::Mat& labels)
{
	cv::Mat overlay = rgb.clone();
	for (int v = 0; v < labels.rows; v++)
		for (int u = 0; u < labels.cols; u++)
			if (labels.at<int8_t>(v, u) == kDiff)
				overlay.at<cv::Vec3b>(v, u) =
				    overlay.at<cv::Vec3b>(v, u) / 2 + cv::Vec3b(0, 0, 127);
	return overlay;
}

}  // namespace bims::flow
