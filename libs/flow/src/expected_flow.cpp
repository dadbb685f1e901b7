#include <bims/flow/expected_flow.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/hal/intrin.hpp>

#include <cfloat>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace bims::flow
{
namespace
{
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

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
                          const mrpt::poses::CPose3D& T_CprevC)
{
	checkDepth(depth, cam);
	const Rt T = rotTrans(T_CprevC);
	const double fx = cam.fx(), fy = cam.fy(), cx = cam.cx(), cy = cam.cy();
	// p = z (xn, yn, 1), so R p + t = z a(u, v) + t with a = R (xn, yn, 1)
	// independent of the depth: per column its xn part (double, once), per
	// row the rest. Per pixel in float: the projection rounds by < 1e-4 px
	// (coordinates of at most a few thousand px), within 1e-3 px of the
	// double-precision formula (tested).
	std::vector<double> xn(depth.cols);
	for (int u = 0; u < depth.cols; u++) xn[u] = (u - cx) / fx;
	std::vector<float> ax(depth.cols), ay(depth.cols), az(depth.cols);
	const float tx = static_cast<float>(T.t[0]),
	            ty = static_cast<float>(T.t[1]),
	            tz = static_cast<float>(T.t[2]);
	const float ffx = static_cast<float>(fx), ffy = static_cast<float>(fy),
	            fcx = static_cast<float>(cx), fcy = static_cast<float>(cy);
	cv::Mat flow(depth.size(), CV_32FC2);
	for (int v = 0; v < depth.rows; v++)
	{
		const double yn = (v - cy) / fy;
		for (int u = 0; u < depth.cols; u++)
		{
			ax[u] = static_cast<float>(T.R[0] * xn[u] + T.R[1] * yn + T.R[2]);
			ay[u] = static_cast<float>(T.R[3] * xn[u] + T.R[4] * yn + T.R[5]);
			az[u] = static_cast<float>(T.R[6] * xn[u] + T.R[7] * yn + T.R[8]);
		}
		const float* zr = depth.ptr<float>(v);
		float* fr = flow.ptr<float>(v);
		const float fv = static_cast<float>(v);
		// Every pixel is computed, the invalid ones then take NaN (z finite
		// and > 0, in front of the previous camera).
		int u = 0;
#if CV_SIMD128
		const cv::v_float32x4 vtx = cv::v_setall_f32(tx),
		                      vty = cv::v_setall_f32(ty),
		                      vtz = cv::v_setall_f32(tz),
		                      vfx = cv::v_setall_f32(ffx),
		                      vfy = cv::v_setall_f32(ffy),
		                      vcx = cv::v_setall_f32(fcx),
		                      vcy = cv::v_setall_f32(fcy),
		                      vfv = cv::v_setall_f32(fv),
		                      zero = cv::v_setall_f32(0.0f),
		                      zmax = cv::v_setall_f32(FLT_MAX),
		                      Zmin = cv::v_setall_f32(1e-6f),
		                      one = cv::v_setall_f32(1.0f),
		                      nan = cv::v_setall_f32(kNaN),
		                      four = cv::v_setall_f32(4.0f);
		cv::v_float32x4 vu(0.0f, 1.0f, 2.0f, 3.0f);
		for (; u + 4 <= depth.cols; u += 4, vu += four)
		{
			const cv::v_float32x4 z = cv::v_load(zr + u);
			const cv::v_float32x4 X = z * cv::v_load(&ax[u]) + vtx;
			const cv::v_float32x4 Y = z * cv::v_load(&ay[u]) + vty;
			const cv::v_float32x4 Z = z * cv::v_load(&az[u]) + vtz;
			const cv::v_float32x4 ok = (z > zero) & (z <= zmax) & (Z > Zmin);
			const cv::v_float32x4 iZ = one / cv::v_select(ok, Z, one);
			cv::v_store_interleave(
			    fr + 2 * u, cv::v_select(ok, vfx * X * iZ + vcx - vu, nan),
			    cv::v_select(ok, vfy * Y * iZ + vcy - vfv, nan));
		}
#endif
		for (; u < depth.cols; u++)
		{
			const float z = zr[u];
			const float X = z * ax[u] + tx, Y = z * ay[u] + ty,
			            Z = z * az[u] + tz;
			const bool ok = z > 0.0f && z <= FLT_MAX && Z > 1e-6f;
			const float iZ = 1.0f / (ok ? Z : 1.0f);
			fr[2 * u] = ok ? ffx * X * iZ + fcx - static_cast<float>(u) : kNaN;
			fr[2 * u + 1] = ok ? ffy * Y * iZ + fcy - fv : kNaN;
		}
	}
	return flow;
}

cv::Mat expectedFlow(ExpectedFlowModel model, const cv::Mat& depth,
                     const mrpt::img::TCamera& cam,
                     const mrpt::poses::CPose3D& T_CprevC)
{
	return model == ExpectedFlowModel::Linear
	           ? expectedFlowLinear(depth, cam, T_CprevC)
	           : expectedFlowExact(depth, cam, T_CprevC);
}

cv::Mat expectedFlowLinear(const cv::Mat& depth, const mrpt::img::TCamera& cam,
                           const mrpt::poses::CPose3D& T_CprevC)
{
	checkDepth(depth, cam);
	// Small-angle rotation vector of R_CprevC.
	cv::Mat Rm(3, 3, CV_64F), rvec;
	const auto& R = T_CprevC.getRotationMatrix();
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++) Rm.at<double>(r, c) = R(r, c);
	cv::Rodrigues(Rm, rvec);
	const double w[3] = {rvec.at<double>(0), rvec.at<double>(1),
	                     rvec.at<double>(2)};
	const double t[3] = {T_CprevC.x(), T_CprevC.y(), T_CprevC.z()};
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
                       const mrpt::poses::CPose3D& R_CprevC)
{
	const Rt T = rotTrans(R_CprevC);
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
                               const mrpt::poses::CPose3D& T_CprevC)
{
	const Rt T = rotTrans(T_CprevC);
	const cv::Matx33d K(cam.fx(), 0, cam.cx(), 0, cam.fy(), cam.cy(), 0, 0, 1);
	const cv::Matx33d R(T.R);
	return K * R * K.inv();
}

}  // namespace bims::flow
