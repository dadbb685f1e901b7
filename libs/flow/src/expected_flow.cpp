#include <bims/flow/expected_flow.h>
#include <opencv2/calib3d.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace bims::flow
{
namespace
{
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

void checkDepth(const cv::Mat& depth, const mrpt::img::TCamera& cam)
{
	if (depth.type() != CV_32FC1)
		throw std::invalid_argument(
		    "expected flow: depth must be CV_32FC1 metres");
	if (depth.cols != static_cast<int>(cam.ncols) ||
	    depth.rows != static_cast<int>(cam.nrows))
		throw std::invalid_argument(
		    "expected flow: depth size differs from the camera's");
}

struct Rt
{
	double R[9];
	double t[3];
};

Rt rotTrans(const mrpt::poses::CPose3D& T)
{
	Rt o{};
	const auto& R = T.getRotationMatrix();
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++) o.R[3 * r + c] = R(r, c);
	o.t[0] = T.x();
	o.t[1] = T.y();
	o.t[2] = T.z();
	return o;
}

inline bool validDepth(float z)
{
	return std::isfinite(z) && z > 0.0f;
}
}  // namespace

void projectionJacobian(const mrpt::img::TCamera& cam,
                        const mrpt::math::TPoint3D& p, double J[6])
{
	const double iz = 1.0 / p.z, iz2 = iz * iz;
	J[0] = cam.fx() * iz;
	J[1] = 0;
	J[2] = -cam.fx() * p.x * iz2;
	J[3] = 0;
	J[4] = cam.fy() * iz;
	J[5] = -cam.fy() * p.y * iz2;
}

cv::Mat expectedFlowExact(const cv::Mat& depth, const mrpt::img::TCamera& cam,
                          const mrpt::poses::CPose3D& T_prev_cur)
{
	checkDepth(depth, cam);
	const Rt T = rotTrans(T_prev_cur);
	const double fx = cam.fx(), fy = cam.fy(), cx = cam.cx(), cy = cam.cy();
	// (u - cx) / fx once per column: the same doubles as per pixel
	std::vector<double> xn(depth.cols);
	for (int u = 0; u < depth.cols; u++) xn[u] = (u - cx) / fx;
	cv::Mat flow(depth.size(), CV_32FC2);
	for (int v = 0; v < depth.rows; v++)
	{
		const float* zr = depth.ptr<float>(v);
		float* fr = flow.ptr<float>(v);
		const double yn = (v - cy) / fy;
		// No branch in the loop (it vectorises): every pixel is computed,
		// the invalid ones then take NaN.
		for (int u = 0; u < depth.cols; u++)
		{
			const double z = zr[u];
			const double x = xn[u] * z, y = yn * z;
			const double X = T.R[0] * x + T.R[1] * y + T.R[2] * z + T.t[0];
			const double Y = T.R[3] * x + T.R[4] * y + T.R[5] * z + T.t[1];
			const double Z = T.R[6] * x + T.R[7] * y + T.R[8] * z + T.t[2];
			const bool ok = z > 0.0 && z < kInf && Z > 1e-6;
			const double iZ = ok ? Z : 1.0;
			const float fu = static_cast<float>(fx * X / iZ + cx - u);
			const float fv = static_cast<float>(fy * Y / iZ + cy - v);
			fr[2 * u] = ok ? fu : kNaN;
			fr[2 * u + 1] = ok ? fv : kNaN;
		}
	}
	return flow;
}

cv::Mat expectedFlowLinear(const cv::Mat& depth, const mrpt::img::TCamera& cam,
                           const mrpt::poses::CPose3D& T_prev_cur)
{
	checkDepth(depth, cam);
	// Small-angle rotation vector of R_prev_cur.
	cv::Mat Rm(3, 3, CV_64F), rvec;
	const auto& R = T_prev_cur.getRotationMatrix();
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++) Rm.at<double>(r, c) = R(r, c);
	cv::Rodrigues(Rm, rvec);
	const double w[3] = {rvec.at<double>(0), rvec.at<double>(1),
	                     rvec.at<double>(2)};
	const double t[3] = {T_prev_cur.x(), T_prev_cur.y(), T_prev_cur.z()};
	const double fx = cam.fx(), fy = cam.fy(), cx = cam.cx(), cy = cam.cy();
	cv::Mat flow(depth.size(), CV_32FC2);
	for (int v = 0; v < depth.rows; v++)
	{
		const float* zr = depth.ptr<float>(v);
		auto* fr = flow.ptr<cv::Vec2f>(v);
		for (int u = 0; u < depth.cols; u++)
		{
			const float z = zr[u];
			if (!validDepth(z))
			{
				fr[u] = {kNaN, kNaN};
				continue;
			}
			const mrpt::math::TPoint3D p((u - cx) / fx * z, (v - cy) / fy * z,
			                             z);
			// dp = w x p + t
			const double dp[3] = {w[1] * p.z - w[2] * p.y + t[0],
			                      w[2] * p.x - w[0] * p.z + t[1],
			                      w[0] * p.y - w[1] * p.x + t[2]};
			double J[6];
			projectionJacobian(cam, p, J);
			fr[u] = {
			    static_cast<float>(J[0] * dp[0] + J[1] * dp[1] + J[2] * dp[2]),
			    static_cast<float>(J[3] * dp[0] + J[4] * dp[1] + J[5] * dp[2])};
		}
	}
	return flow;
}

cv::Mat homographyFlow(const mrpt::img::TCamera& cam,
                       const mrpt::poses::CPose3D& R_prev_cur)
{
	const Rt T = rotTrans(R_prev_cur);
	const double fx = cam.fx(), fy = cam.fy(), cx = cam.cx(), cy = cam.cy();
	cv::Mat flow(static_cast<int>(cam.nrows), static_cast<int>(cam.ncols),
	             CV_32FC2);
	for (int v = 0; v < flow.rows; v++)
	{
		auto* fr = flow.ptr<cv::Vec2f>(v);
		for (int u = 0; u < flow.cols; u++)
		{
			// H = K R K^-1 on the homogeneous pixel.
			const double x = (u - cx) / fx, y = (v - cy) / fy;
			const double X = T.R[0] * x + T.R[1] * y + T.R[2];
			const double Y = T.R[3] * x + T.R[4] * y + T.R[5];
			const double Z = T.R[6] * x + T.R[7] * y + T.R[8];
			if (Z <= 1e-9)
			{
				fr[u] = {kNaN, kNaN};
				continue;
			}
			fr[u] = {static_cast<float>(fx * X / Z + cx - u),
			         static_cast<float>(fy * Y / Z + cy - v)};
		}
	}
	return flow;
}

cv::Matx33d rotationHomography(const mrpt::img::TCamera& cam,
                               const mrpt::poses::CPose3D& T_prev_cur)
{
	const Rt T = rotTrans(T_prev_cur);
	const cv::Matx33d K(cam.fx(), 0, cam.cx(), 0, cam.fy(), cam.cy(), 0, 0, 1);
	const cv::Matx33d R(T.R);
	return K * R * K.inv();
}

}  // namespace bims::flow
