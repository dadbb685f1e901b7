#include <bims/ego/moving_prediction.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bims::ego
{
cv::Mat predictMovingMask(const cv::Mat& movingPrev, const cv::Mat& depthPrev,
                          const Eigen::Matrix3d& K,
                          const Eigen::Matrix3d& R_CprevC,
                          const Eigen::Vector3d& t_CprevC, int margin_px)
{
	if (movingPrev.type() != CV_8UC1 || depthPrev.type() != CV_32FC1 ||
	    movingPrev.size() != depthPrev.size())
		throw std::invalid_argument(
		    "predictMovingMask: expected an 8-bit mask and a float depth "
		    "image of one size");
	if (margin_px < 0)
		throw std::invalid_argument("predictMovingMask: margin_px < 0");
	const int W = movingPrev.cols, H = movingPrev.rows;
	cv::Mat out = cv::Mat::zeros(movingPrev.size(), CV_8UC1);
	const double fx = K(0, 0), fy = K(1, 1), cx = K(0, 2), cy = K(1, 2);
	// p_cur = R^T (p_prev - t), with p_prev = z (xn, yn, 1)
	const Eigen::Matrix3d Rt = R_CprevC.transpose();
	const Eigen::Vector3d b = -Rt * t_CprevC;
	constexpr int kStep = 2;
	constexpr double kMaxHalf = 32;
	for (int v = 0; v < H; v += kStep)
	{
		const uint8_t* m = movingPrev.ptr<uint8_t>(v);
		const float* d = depthPrev.ptr<float>(v);
		const double yn = (v - cy) / fy;
		for (int u = 0; u < W; u += kStep)
		{
			if (!m[u] || !(d[u] > 0)) continue;
			const double z = d[u];
			const Eigen::Vector3d p =
			    z * Rt * Eigen::Vector3d((u - cx) / fx, yn, 1) + b;
			if (!(p.z() > 1e-3)) continue;
			const double uc = fx * p.x() / p.z() + cx,
			             vc = fy * p.y() / p.z() + cy;
			// a reading of the kStep grid covers kStep pixels at depth z,
			// kStep z / z' pixels at depth z' (at most kMaxHalf a side)
			const int h = static_cast<int>(
			    std::min(kMaxHalf, std::ceil(0.5 * kStep * z / p.z())));
			if (!(uc > -h && uc < W + h && vc > -h && vc < H + h)) continue;
			const int u0 =
			              std::max(0, static_cast<int>(std::floor(uc)) - h + 1),
			          u1 =
			              std::min(W - 1, static_cast<int>(std::floor(uc)) + h),
			          v0 =
			              std::max(0, static_cast<int>(std::floor(vc)) - h + 1),
			          v1 =
			              std::min(H - 1, static_cast<int>(std::floor(vc)) + h);
			for (int y = v0; y <= v1; y++)
			{
				uint8_t* o = out.ptr<uint8_t>(y);
				for (int x = u0; x <= u1; x++) o[x] = 255;
			}
		}
	}
	if (margin_px > 0)
		cv::dilate(out, out,
		           cv::getStructuringElement(
		               cv::MORPH_RECT,
		               cv::Size(2 * margin_px + 1, 2 * margin_px + 1)));
	return out;
}

}  // namespace bims::ego
