#include <bims/eval/depth_consistency.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace bims::eval
{
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
			const long uj = std::lround(cam.fx * X / Z + cam.cx);
			const long vj = std::lround(cam.fy * Y / Z + cam.cy);
			if (uj < 0 || vj < 0 || uj >= depth_j.cols || vj >= depth_j.rows)
				continue;
			const double zj =
			    depth_j.at<float>(static_cast<int>(vj), static_cast<int>(uj));
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
