#include <bims/pipeline/mask_overlay.h>

#include <opencv2/imgproc.hpp>

namespace bims::pipeline
{
cv::Mat overlayMoving(const cv::Mat& bgr, const cv::Mat& maskIn)
{
	cv::Mat out;
	if (bgr.channels() == 1)
		cv::cvtColor(bgr, out, cv::COLOR_GRAY2BGR);
	else
		out = bgr.clone();
	if (maskIn.empty() || out.empty()) return out;
	cv::Mat mask = maskIn;
	if (mask.size() != out.size())
		cv::resize(maskIn, mask, out.size(), 0, 0, cv::INTER_NEAREST);
	const cv::Mat red(out.size(), CV_8UC3, cv::Scalar(0, 0, 255));
	cv::Mat blended;
	cv::addWeighted(out, 0.5, red, 0.5, 0, blended);
	blended.copyTo(out, mask);
	return out;
}

}  // namespace bims::pipeline
