// Pose helpers for ground truth: interpolation and the Bonn RGB-D Dynamic
// dataset's marker-to-camera conversion.
#pragma once

#include <bims/io/trajectory.h>
#include <mrpt/poses/CPose3D.h>

#include <optional>

namespace bims::eval
{
/** The pose of \a traj at time \a t [s]: linear interpolation of the
 * translation and slerp of the rotation between the two poses bracketing t.
 * Returns nullopt if t is outside the trajectory or the bracketing poses are
 * more than \a maxGap seconds apart. \a traj must be sorted by time. */
std::optional<mrpt::poses::CPose3D> interpolatePose(const Trajectory& traj,
                                                    double t, double maxGap);

/** Bonn RGB-D Dynamic dataset: camera pose from the ground-truth marker pose.
 * The dataset documents T_cam = T_ros * T_gt * T_ros * T_m (T_ros an axis
 * swap, T_m marker to camera). The leftmost T_ros only changes the basis of
 * the world to a y-up one; we return T_WC = T_gt * T_ros * T_m, i.e. the
 * same camera motion expressed in the motion-capture world, which is z up
 * like the project's {W} (heading arbitrary). Relative poses, and so ATE and
 * RPE, are identical for both forms. The 3x3 block of the published T_m is
 * not exactly orthonormal (singular values ~1.06, 1.05, 1.0); we use its
 * nearest rotation (polar decomposition, SVD) and its translation so that
 * the result is rigid (depth registration with the raw affine T_m is within
 * 1 mm of ours). Verified by depth registration (tests/test_bonn.cpp,
 * docs/eval.md). Returns T_WC of the optical frame {C}. */
mrpt::poses::CPose3D bonnMarkerToCamera(const mrpt::poses::CPose3D& T_gt);

/** The published 4x4 T_m as given (not orthonormalised), row-major. */
const double* bonnTm4x4();

}  // namespace bims::eval
