// Dense observed optical flow between two grey images (OpenCV DIS or
// Farneback), backward convention: flow(u) = u_{t-1} - u_t on frame t's pixels.
#pragma once

#include <bims/flow/params.h>
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

namespace bims::flow
{
class ObservedFlow
{
 public:
	explicit ObservedFlow(const FlowParams& p = {});

	/** Backward flow of \a cur (frame t) towards \a prev (frame t-1), both
	 * CV_8UC1 of the same size. Returns CV_32FC2 of that size. Throws
	 * std::invalid_argument on empty or mismatched images. */
	cv::Mat compute(const cv::Mat& prev, const cv::Mat& cur);

 private:
	FlowParams p_;
	cv::Ptr<cv::DISOpticalFlow> dis_;
};

}  // namespace bims::flow
