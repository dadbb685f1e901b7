#include <bims/eval/depth_consistency.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace bims::eval
{
namespace
{
/** Depth at sub-pixel (u, v): bilinear where the 4 neighbours are valid
 * and within 5 cm of each other (one surface), else the nearest pixel.
 * 0 outside the image or where there is no reading. */
double sampleDepth(const cv::Mat& d, double u, double v)
{
	const long un = std::lround(u), vn = std::lround(v);
	if (un < 0 || vn < 0 || un >= d.cols || vn >= d.rows) return 0;
	const int u0 = static_cast<int>(std::floor(u)),
	          v0 = static_cast<int>(std::floor(v));
	if (u0 >= 0 && v0 >= 0 && u0 + 1 < d.cols && v0 + 1 < d.rows)
	{
		const float z00 = d.at<float>(v0, u0), z01 = d.at<float>(v0, u0 + 1),
		            z10 = d.at<float>(v0 + 1, u0),
		            z11 = d.at<float>(v0 + 1, u0 + 1);
		const float lo = std::min({z00, z01, z10, z11}),
		            hi = std::max({z00, z01, z10, z11});
		if (lo > 0 && hi - lo < 0.05f)
		{
			const double a = u - u0, b = v - v0;
			return (1 - b) * ((1 - a) * z00 + a * z01) +
			       b * ((1 - a) * z10 + a * z11);
		}
	}
	return d.at<float>(static_cast<int>(vn), static_cast<int>(un));
}
}  // namespace

DepthAgreement depthAgreement(const cv::Mat& depth_i,
                              const mrpt::poses::CPose3D& T_WC_i,
                              const cv::Mat& depth_j,
                              const mrpt::poses::CPose3D& T_WC_j,
                              const CameraIntrinsics& cam, int step)
{
	if (depth_i.type() != CV_32FC1 || depth_j.type() != CV_32FC1 ||
	    depth_i.size() != depth_j.size())
		throw std::invalid_argument(
		    "depthAgreement: depth images must be CV_32F of the same size");
	step = std::max(1, step);
	// p_Cj = T_CjCi p_Ci
	const mrpt::poses::CPose3D T_CjCi = T_WC_i - T_WC_j;  // T_WC_j^-1 T_WC_i
	const auto R = T_CjCi.getRotationMatrix();
	const double tx = T_CjCi.x(), ty = T_CjCi.y(), tz = T_CjCi.z();
	std::vector<double> res;
	for (int v = 0; v < depth_i.rows; v += step)
		for (int u = 0; u < depth_i.cols; u += step)
		{
			const double z = depth_i.at<float>(v, u);
			if (!(z > 0)) continue;
			const double x = (u - cam.cx) / cam.fx * z,
			             y = (v - cam.cy) / cam.fy * z;
			const double X = R(0, 0) * x + R(0, 1) * y + R(0, 2) * z + tx;
			const double Y = R(1, 0) * x + R(1, 1) * y + R(1, 2) * z + ty;
			const double Z = R(2, 0) * x + R(2, 1) * y + R(2, 2) * z + tz;
			if (Z <= 0.05) continue;
			const double fu = cam.fx * X / Z + cam.cx,
			             fv = cam.fy * Y / Z + cam.cy;
			const double zj = sampleDepth(depth_j, fu, fv);
			if (!(zj > 0)) continue;
			res.push_back(std::abs(zj - Z));
		}
	DepthAgreement a;
	a.compared = res.size();
	if (res.empty()) return a;
	size_t within5 = 0, within20 = 0;
	double sum20 = 0;
	for (const double r : res)
	{
		if (r < 0.05) within5++;
		if (r < 0.20)
		{
			within20++;
			sum20 += r;
		}
	}
	a.fractionWithin5cm = static_cast<double>(within5) / res.size();
	a.meanAbsWithin20cm = within20 ? sum20 / within20 : 0;
	std::nth_element(res.begin(), res.begin() + res.size() / 2, res.end());
	a.medianAbs = res[res.size() / 2];
	return a;
}

cv::Mat depthFromObservation(const mrpt::obs::CObservation3DRangeScan& obs)
{
	if (!obs.hasRangeImage)
		throw std::invalid_argument("3D scan has no range image");
	if (!obs.range_is_depth)
		throw std::invalid_argument("3D scan range image is not Z-depth");
	const auto& r = obs.rangeImage;
	cv::Mat m(static_cast<int>(r.rows()), static_cast<int>(r.cols()), CV_32F);
	for (int v = 0; v < m.rows; v++)
		for (int u = 0; u < m.cols; u++)
			m.at<float>(v, u) = r(v, u) * obs.rangeUnits;
	return m;
}

CameraIntrinsics intrinsicsFromObservation(
    const mrpt::obs::CObservation3DRangeScan& obs)
{
	CameraIntrinsics c;
	c.fx = obs.cameraParams.fx();
	c.fy = obs.cameraParams.fy();
	c.cx = obs.cameraParams.cx();
	c.cy = obs.cameraParams.cy();
	c.width = static_cast<int>(obs.cameraParams.ncols);
	c.height = static_cast<int>(obs.cameraParams.nrows);
	return c;
}

}  // namespace bims::eval
