// The moving region of the previous frame predicted into this one.
//
// The pipeline's moving mask of frame t-1 is the image of the voxels its
// decision tier labelled moving, read per depth reading. Each masked reading
// of t-1 is a 3D point of a mover; moved with the predicted camera motion
// T_C(t-1)C(t) and projected into frame t, it marks where that mover is
// expected now (up to its own motion, which the margin covers). The
// previous mask as it is would be off by the camera's motion.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace bims::ego
{
/** Predicts \a movingPrev (CV_8UC1, non-zero = moving in frame t-1) into
 * frame t. \param depthPrev metric depth of t-1 (CV_32FC1, 0 = none) of the
 * same size. \param K intrinsics of both frames. \param R_CprevC,
 * t_CprevC the predicted motion: p_{C(t-1)} = R p_{C(t)} + t. Every second
 * masked reading in each direction is projected and drawn as a square of
 * its footprint; the result is dilated by \a margin_px (a square of side
 * 2 margin_px + 1). Masked pixels without depth are left out. Returns
 * CV_8UC1 of the image size, 255 = predicted moving. */
cv::Mat predictMovingMask(const cv::Mat& movingPrev, const cv::Mat& depthPrev,
                          const Eigen::Matrix3d& K,
                          const Eigen::Matrix3d& R_CprevC,
                          const Eigen::Vector3d& t_CprevC, int margin_px);

}  // namespace bims::ego
