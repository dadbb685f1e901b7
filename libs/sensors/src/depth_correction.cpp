#include <bims/sensors/camera.h>
#include <bims/sensors/depth_correction.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>

namespace bims::sensors
{
std::array<double, kDepthCorrectionTerms> depthCorrectionBasis(double x,
                                                               double y)
{
	const double x2 = x * x, y2 = y * y;
	return {x,      y,      x2,     x * y,   y2,      x2 * x,
	        x2 * y, x * y2, y2 * y, x2 * x2, y2 * y2, x2 * y2};
}

double depthCorrectionDelta(const DepthCorrectionParams& p, double x, double y)
{
	const auto b = depthCorrectionBasis(x, y);
	double d = 0;
	for (int i = 0; i < kDepthCorrectionTerms; i++)
		d += p.coefficients[i] * b[i];
	return d;
}

const cv::Mat& DepthCorrection::factors(const Eigen::Matrix3d& K, cv::Size size)
{
	if (f_.size() == size && K == K_) return f_;
	K_ = K;
	f_.create(size, CV_32FC1);
	const double fx = K(0, 0), fy = K(1, 1), cx = K(0, 2), cy = K(1, 2);
	for (int v = 0; v < size.height; v++)
	{
		float* o = f_.ptr<float>(v);
		for (int u = 0; u < size.width; u++)
		{
			o[u] = static_cast<float>(
			    1 + depthCorrectionDelta(p_, (u - cx) / fx, (v - cy) / fy));
		}
	}
	return f_;
}

void DepthCorrection::apply(cv::Mat& depth, const Eigen::Matrix3d& K)
{
	if (!p_.enable) return;
	CV_Assert(depth.type() == CV_32FC1);
	cv::multiply(depth, factors(K, depth.size()), depth);
}

void DepthCorrection::apply(mrpt::obs::CObservation3DRangeScan& obs,
                            const CameraParams& cam)
{
	if (!p_.enable || !obs.hasRangeImage) return;
	obs.load();
	auto& img = obs.rangeImage;
	const int H = static_cast<int>(img.rows()),
	          W = static_cast<int>(img.cols());
	Eigen::Matrix3d K;
	// (unusable intrinsics: left to rgbdFrameFrom() to report)
	if (!intrinsicsOf(obs, cam, K).empty()) return;
	const cv::Mat& f = factors(K, cv::Size(W, H));
	for (int v = 0; v < H; v++)
	{
		const float* fr = f.ptr<float>(v);
		for (int u = 0; u < W; u++)
		{
			const uint16_t z = img(v, u);
			if (z == 0) continue;
			const float c = std::round(z * fr[u]);
			img(v, u) = static_cast<uint16_t>(std::clamp(c, 1.f, 65535.f));
		}
	}
}

}  // namespace bims::sensors
