// Relative camera pose from the dense observed flow over the static majority.
//
// The expected flow is only as good as T_CprevC. On real data the feature
// egomotion (and above all a poor or synthetic IMU rotation) leaves errors of
// a few pixels of flow, far above diff_threshold_px. refinePoseWithFlow()
// fits T_CprevC to the observed flow of a grid of pixels with depth
// (robust Gauss-Newton: Huber, then Tukey with a MAD scale), so that the
// pixels of independently moving objects, a minority, are ignored.
#pragma once

#include <bims/flow/params.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>
#include <opencv2/core.hpp>

#include <Eigen/Core>
#include <string>

namespace bims::flow
{
/** What refinePoseWithFlow() estimates. */
enum class FlowPoseMode
{
	Translation,  ///< keep the rotation of the initial pose (e.g. the IMU's)
	SE3           ///< rotation and translation (vision only)
};

struct FlowPoseParams
{
	FlowPoseMode mode = FlowPoseMode::SE3;
	int step_px = 4;        ///< sample every step_px-th pixel in u and v
	int iterations = 12;    ///< Gauss-Newton iterations
	double huber_px = 1.0;  ///< Huber scale of the first iterations [px]
	/** Tukey cut-off in robust standard deviations (MAD) of the residuals,
	 * clamped to [tukey_min_px, tukey_max_px] [px]: the upper limit keeps a
	 * large coherent mover from inflating the scale until it fits. */
	double tukey_sigmas = 4.0;
	double tukey_min_px = 1.5;
	double tukey_max_px = 3.0;
	double min_depth_m = 0.3, max_depth_m = 6.0;  ///< depth readings used
	/** Samples whose depth differs from a neighbour's by more than this
	 * fraction of their depth lie on an occlusion edge: not used. */
	double edge_rel = 0.05;
	int min_samples = 200;  ///< fewer usable samples: keep the initial pose
	/** With a structure tensor: samples need its minimum eigenvalue at least
	 * this [(grey/px)^2] (flow on textureless surfaces is not measured). */
	double min_texture = 4.0;
};

struct FlowPoseResult
{
	mrpt::poses::CPose3D T_CprevC;  ///< refined (or initial, when !ok)
	bool ok = false;                ///< false: the initial pose is kept
	int samples = 0;                ///< pixels used
	double inlier_fraction = 0;     ///< of the final Tukey weights > 0
	double median_px_before = 0;    ///< median |obs - exp| of the samples
	double median_px_after = 0;     ///< ... with the refined pose
};

/** Fits T_CprevC = T_{C(t-1) C(t)} to the backward observed flow
 * (CV_32FC2, u_{t-1} - u_t, NaN = none) on the current frame's pixels with
 * the current \a depth (CV_32FC1 metres), starting from \a init. Pixels with
 * non-zero \a exclude (CV_8UC1, optional: e.g. the previous moving mask) are
 * not used; with \a tensor (structureTensor() of the current image) only
 * textured pixels are. Throws std::invalid_argument on mismatched inputs. */
FlowPoseResult refinePoseWithFlow(const cv::Mat& observed, const cv::Mat& depth,
                                  const mrpt::img::TCamera& cam,
                                  const mrpt::poses::CPose3D& init,
                                  const FlowPoseParams& p,
                                  const cv::Mat* exclude = nullptr,
                                  const cv::Mat* tensor = nullptr);

/** refinePoseWithFlow()'s Gauss-Newton Jacobian of one sample: the 2x6
 * Jacobian of the projection (fx x / z + cx, fy y / z + cy) of
 * q = R p + t = (x, y, z) (the sample in the previous camera) w.r.t. the
 * increment (w, v) (rotation first [rad], then translation [m]) applied on
 * the left, as the fit applies it: R <- Exp(w) R, t <- Exp(w) t + v. The
 * flow residual (observed - projection) has minus this Jacobian. */
Eigen::Matrix<double, 2, 6> flowPoseJacobian(const Eigen::Vector3d& q,
                                             double fx, double fy);

/** The [flow] refine_* keys as FlowPoseParams (mode from refine_pose,
 * which must not be "none"; depth range up to max_depth_m). */
FlowPoseParams flowPoseParamsFrom(const FlowParams& p);

/** Marks depth discontinuities: 255 where the depth of a pixel and one of its
 * 8 neighbours within \a radius px differ by more than \a rel times the
 * nearer one, or where a neighbour has no reading (0 / NaN) and the pixel
 * has. CV_8UC1 of the depth's size. */
cv::Mat depthEdgeMask(const cv::Mat& depth, double rel, int radius);

}  // namespace bims::flow
