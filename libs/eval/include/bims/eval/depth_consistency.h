// Check of ground-truth poses with depth: back-project the depth of frame i
// with T_WC_i, transform into frame j with T_WC_j^-1, project, and compare
// with frame j's depth. Correct poses make the two agree to the sensor noise
// wherever the same static surface is seen.
#pragma once

#include <bims/eval/tum_import.h>
#include <bims/io/trajectory.h>

#include <opencv2/core.hpp>

namespace bims::eval
{
struct DepthAgreement
{
	size_t compared = 0;           ///< pixels of i landing on valid depth in j
	double medianAbs = 0;          ///< median |z_j(u') - z_i->j| [m]
	double fractionWithin5cm = 0;  ///< share of compared with |dz| < 5 cm
	double meanAbsWithin20cm = 0;  ///< mean |dz| over those below 20 cm [m]
};

/** Compares depth images \a depth_i and \a depth_j (CV_32F metres, 0 =
 * invalid; pinhole \a cam, no distortion) under the poses T_WC_i, T_WC_j
 * (optical frames). \a step subsamples pixels of i (every step-th row and
 * column). */
DepthAgreement depthAgreement(const cv::Mat& depth_i,
                              const mrpt::poses::CPose3D& T_WC_i,
                              const cv::Mat& depth_j,
                              const mrpt::poses::CPose3D& T_WC_j,
                              const CameraIntrinsics& cam, int step = 2);

}  // namespace bims::eval

namespace bims::eval
{
/** The range image of a 3D scan as metres, CV_32F (0 = invalid). Throws if
 * the observation has no range image or it is not Z-depth. */
cv::Mat depthFromObservation(const mrpt::obs::CObservation3DRangeScan& obs);

/** The scan's intrinsics (fx fy cx cy width height; depthScale unused). */
CameraIntrinsics intrinsicsFromObservation(
    const mrpt::obs::CObservation3DRangeScan& obs);
}  // namespace bims::eval
