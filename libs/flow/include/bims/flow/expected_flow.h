// Optical flow expected from depth and egomotion, for a static scene.
//
// Convention: flows are *backward*, defined on the pixels of the current frame
// t: flow(u) = u_{t-1} - u_t, the displacement to where the same world point
// was seen at t-1. The labels of the current frame's pixels therefore come
// with the current depth. Frames are optical ({C}: x right, y down, z fwd).
#pragma once

#include <bims/flow/params.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/math/TPoint3D.h>
#include <mrpt/poses/CPose3D.h>
#include <opencv2/core.hpp>

namespace bims::flow
{
/** Pinhole projection of p_C (z > 0) with \a cam's fx, fy, cx, cy. */
inline cv::Point2d project(const mrpt::img::TCamera& cam,
                           const mrpt::math::TPoint3D& p_C)
{
	return {cam.fx() * p_C.x / p_C.z + cam.cx(),
	        cam.fy() * p_C.y / p_C.z + cam.cy()};
}

/** Back-projection of pixel (u, v) with depth z [m] to p_C. */
inline mrpt::math::TPoint3D backProject(const mrpt::img::TCamera& cam, double u,
                                        double v, double z)
{
	return {(u - cam.cx()) * z / cam.fx(), (v - cam.cy()) * z / cam.fy(), z};
}

/** The 2x3 Jacobian d(u,v)/d(x,y,z) of project() at p_C (row major, J[6]). */
void projectionJacobian(const mrpt::img::TCamera& cam,
                        const mrpt::math::TPoint3D& p_C, double J[6]);

/** Exact expected backward flow: each current pixel with depth z > 0 is
 * back-projected, moved to the previous camera frame with
 * T_CprevC = T_{C(t-1) C(t)} and projected. \a depth is CV_32FC1 metres
 * (0 or non-finite = no reading). Output CV_32FC2; NaN where there is no
 * depth or the point falls behind the previous camera. */
cv::Mat expectedFlowExact(const cv::Mat& depth, const mrpt::img::TCamera& cam,
                          const mrpt::poses::CPose3D& T_CprevC);

/** First-order expected flow (paper eq. 8): du = J(p) * dp with
 * dp = [theta]x p + t (small-angle rotation vector theta of T_CprevC).
 * Same conventions as expectedFlowExact(). */
cv::Mat expectedFlowLinear(const cv::Mat& depth, const mrpt::img::TCamera& cam,
                           const mrpt::poses::CPose3D& T_CprevC);

/** The expected flow of [flow] expected: expectedFlowExact() or
 * expectedFlowLinear(). */
cv::Mat expectedFlow(ExpectedFlowModel model, const cv::Mat& depth,
                     const mrpt::img::TCamera& cam,
                     const mrpt::poses::CPose3D& T_CprevC);

/** Flow of a pure rotation R_CprevC, independent of depth: the infinite
 * homography H = K R K^-1 applied to every pixel (CV_32FC2, width x height of
 * \a cam). */
cv::Mat homographyFlow(const mrpt::img::TCamera& cam,
                       const mrpt::poses::CPose3D& R_CprevC);

/** The infinite homography H = K R K^-1 of the rotation of \a T_CprevC
 * (its translation is ignored): maps a current pixel (u, v, 1) to where a
 * point at infinity seen there was seen in the previous frame. */
cv::Matx33d rotationHomography(const mrpt::img::TCamera& cam,
                               const mrpt::poses::CPose3D& T_CprevC);

}  // namespace bims::flow
