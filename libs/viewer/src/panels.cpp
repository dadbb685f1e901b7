#include <bims/pipeline/mask_overlay.h>
#include <bims/viewer/panels.h>

#include <mrpt/img/CImage.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace bims::viewer
{
namespace
{
double percentile99(std::vector<float>& v)
{
	if (v.empty()) return 0;
	const size_t k = static_cast<size_t>(0.99 * (v.size() - 1));
	std::nth_element(v.begin(), v.begin() + k, v.end());
	return v[k];
}
}  // namespace

cv::Mat intensityBgr(const mrpt::obs::CObservation3DRangeScan& scan)
{
	if (!scan.hasIntensityImage || scan.intensityImage.isEmpty())
		return cv::Mat();
	const cv::Mat m = scan.intensityImage.asCvMatRef();
	cv::Mat out;
	if (m.channels() == 1)
		cv::cvtColor(m, out, cv::COLOR_GRAY2BGR);
	else
		out = m.clone();  // CImage holds BGR
	return out;
}

cv::Mat overlayMask(const cv::Mat& bgr, const cv::Mat& maskIn)
{
	cv::Mat out = pipeline::overlayMoving(bgr, maskIn);
	if (maskIn.empty() || bgr.empty()) return out;
	cv::Mat mask = maskIn;
	if (mask.size() != bgr.size())
		cv::resize(maskIn, mask, bgr.size(), 0, 0, cv::INTER_NEAREST);
	std::vector<std::vector<cv::Point>> contours;
	cv::findContours(mask.clone(), contours, cv::RETR_EXTERNAL,
	                 cv::CHAIN_APPROX_SIMPLE);
	cv::drawContours(out, contours, -1, cv::Scalar(0, 0, 255), 1);
	return out;
}

cv::Mat depthColour(const mrpt::obs::CObservation3DRangeScan& scan,
                    double maxDepthM)
{
	if (!scan.hasRangeImage) return cv::Mat();
	const auto& R = scan.rangeImage;
	const int h = static_cast<int>(R.rows()), w = static_cast<int>(R.cols());
	cv::Mat d(h, w, CV_32FC1);
	std::vector<float> valid;
	valid.reserve(static_cast<size_t>(w) * h);
	for (int v = 0; v < h; ++v)
		for (int u = 0; u < w; ++u)
		{
			const float z = R(v, u) * scan.rangeUnits;
			d.at<float>(v, u) = z;
			if (z > 0) valid.push_back(z);
		}
	if (maxDepthM <= 0) maxDepthM = percentile99(valid);
	if (maxDepthM <= 0) maxDepthM = 1;
	cv::Mat u8;
	d.convertTo(u8, CV_8UC1, 255.0 / maxDepthM);
	cv::Mat out;
	cv::applyColorMap(u8, out, cv::COLORMAP_JET);
	out.setTo(cv::Scalar(0, 0, 0), d <= 0);
	return out;
}

cv::Mat flowColour(const cv::Mat& flow, double maxMagPx, cv::Size size)
{
	if (flow.empty()) return cv::Mat(size, CV_8UC3, cv::Scalar(64, 64, 64));
	CV_Assert(flow.type() == CV_32FC2);
	std::vector<float> mags;
	mags.reserve(flow.total());
	for (int v = 0; v < flow.rows; ++v)
		for (int u = 0; u < flow.cols; ++u)
		{
			const auto f = flow.at<cv::Vec2f>(v, u);
			if (std::isfinite(f[0]) && std::isfinite(f[1]))
				mags.push_back(std::hypot(f[0], f[1]));
		}
	if (maxMagPx <= 0) maxMagPx = percentile99(mags);
	if (maxMagPx <= 1e-6) maxMagPx = 1;
	cv::Mat hsv(flow.size(), CV_8UC3, cv::Scalar(0, 0, 0));
	for (int v = 0; v < flow.rows; ++v)
		for (int u = 0; u < flow.cols; ++u)
		{
			const auto f = flow.at<cv::Vec2f>(v, u);
			if (!std::isfinite(f[0]) || !std::isfinite(f[1])) continue;
			const double ang = std::atan2(f[1], f[0]);  // [-pi, pi]
			const double hue = (ang + M_PI) / (2 * M_PI) * 180.0;
			const double val =
			    std::min(1.0, std::hypot(f[0], f[1]) / maxMagPx) * 255.0;
			hsv.at<cv::Vec3b>(v, u) =
			    cv::Vec3b(static_cast<uint8_t>(std::min(179.0, hue)), 255,
			              static_cast<uint8_t>(val));
		}
	cv::Mat out;
	cv::cvtColor(hsv, out, cv::COLOR_HSV2BGR);
	return out;
}

cv::Mat placeholderPanel(cv::Size size, const std::string& why)
{
	cv::Mat img(size, CV_8UC3, cv::Scalar(64, 64, 64));
	const int font = cv::FONT_HERSHEY_SIMPLEX;
	int base = 0;
	const cv::Size t = cv::getTextSize(why, font, 1.0, 2, &base);
	// scaled to 80 % of the width at most
	const double scale = std::min(1.0, 0.8 * size.width / std::max(1, t.width));
	const cv::Size ts(static_cast<int>(t.width * scale),
	                  static_cast<int>(t.height * scale));
	cv::putText(img, why,
	            {(size.width - ts.width) / 2, (size.height + ts.height) / 2},
	            font, scale, cv::Scalar(200, 200, 200),
	            std::max(1, static_cast<int>(2 * scale)), cv::LINE_AA);
	return img;
}

cv::Mat labelsColour(const cv::Mat& labels, const cv::Mat& bgr)
{
	cv::Mat grey, out;
	if (bgr.empty())
		out = cv::Mat(labels.size(), CV_8UC3, cv::Scalar(0, 0, 0));
	else
	{
		cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
		grey = grey / 2;
		cv::cvtColor(grey, out, cv::COLOR_GRAY2BGR);
	}
	if (labels.empty()) return out;
	CV_Assert(labels.type() == CV_8SC1 && labels.size() == out.size());
	out.setTo(cv::Scalar(0, 160, 0), labels == 0);
	out.setTo(cv::Scalar(0, 0, 255), labels == 1);
	return out;
}

TierColours tierColourFractions(const cv::Mat& bgr)
{
	TierColours c;
	if (bgr.empty()) return c;
	CV_Assert(bgr.type() == CV_8UC3);
	cv::Mat hsv;
	cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);  // H in [0, 180)
	size_t nb = 0, ny = 0, nr = 0;
	for (int v = 0; v < hsv.rows; ++v)
		for (int u = 0; u < hsv.cols; ++u)
		{
			const auto p = hsv.at<cv::Vec3b>(v, u);
			if (p[1] < 90 || p[2] < 90) continue;
			if (p[0] >= 110 && p[0] <= 130)
				++nb;
			else if (p[0] >= 22 && p[0] <= 38)
				++ny;
			else if (p[0] <= 6 || p[0] >= 174)
				++nr;
		}
	const double n = static_cast<double>(bgr.total());
	c.blue = nb / n;
	c.yellow = ny / n;
	c.red = nr / n;
	return c;
}

}  // namespace bims::viewer
