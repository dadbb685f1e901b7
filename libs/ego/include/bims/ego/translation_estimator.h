// TranslationEstimator: camera motion between two frames from tracked
// features with depth, robust to features on independently moving objects.
//
// Motion model: T_CprevC = (R, t), the current camera in the previous one,
// so a static point satisfies p_prev = R p_cur + t. With R known from the IMU
// this is the paper's eq. (2) in the rotation-compensated frame {R}:
// Q_prev - Q_cur = R_WCprev t, with Q = R_WC p (points rotated to the world
// axes), i.e. the camera translation is the common displacement of the static
// points; features on moving objects are the outliers.
//   estimateTranslation: 1-point RANSAC (or LMedS) on t, then weighted least
//     squares over the inliers (the mean of p_prev - R p_cur).
//   estimateSE3: vision only, 3-point RANSAC + weighted Kabsch/Horn.
//   refineSE3: Gauss-Newton over R and t on the inliers with a rotation
//     prior (the IMU), robust Huber weights: the IMU/vision rotation fusion.
// Inlier test: |p_prev - R p_cur - t| < a + b z^2 (z: depth of p_prev).
#pragma once

#include <bims/ego/params.h>

#include <Eigen/Core>

#include <vector>

namespace bims::ego
{
/** One tracked feature with depth in both frames (optical frames, metres). */
struct Correspondence
{
	Eigen::Vector3d p_prev;  ///< point in {C_prev} [m]
	Eigen::Vector3d p_cur;   ///< point in {C_cur} [m]
	/** Pixels of the feature (needed by refineReprojection only) [px]. */
	Eigen::Vector2d x_prev = Eigen::Vector2d::Zero();
	Eigen::Vector2d x_cur = Eigen::Vector2d::Zero();
};

/** Result of one estimate. */
struct MotionEstimate
{
	bool ok = false;  ///< enough inliers (>= min_inliers)
	Eigen::Matrix3d R_CprevC = Eigen::Matrix3d::Identity();
	Eigen::Vector3d t_CprevC = Eigen::Vector3d::Zero();  ///< [m]
	std::vector<uint8_t> inlier;                         ///< per correspondence
	int inliers = 0;
	double residual_rms_m = 0;  ///< RMS 3D residual of the inliers [m]
};

class TranslationEstimator
{
 public:
	explicit TranslationEstimator(const TranslationParams& p = {});

	/** Translation with a known rotation R_CprevC (IMU mode). */
	MotionEstimate estimateTranslation(const std::vector<Correspondence>& c,
	                                   const Eigen::Matrix3d& R_CprevC) const;

	/** Full SE(3) from the correspondences alone (vision-only mode). */
	MotionEstimate estimateSE3(const std::vector<Correspondence>& c) const;

	/** Refines \a init over its inliers: minimises sum Huber(|r_i|/s_i) +
	 * |Log(R_prior^T R)|^2 / sigma_prior^2, r_i = R p_cur + t - p_prev,
	 * s_i = point_sigma_m max(z_i, 1)^2. Inliers are re-evaluated. */
	MotionEstimate refineSE3(const std::vector<Correspondence>& c,
	                         const MotionEstimate& init,
	                         const Eigen::Matrix3d& R_prior,
	                         double sigmaPrior_rad) const;

	/** Inlier threshold for a point at depth z [m]. */
	double threshold(double z) const
	{
		return p_.inlier_threshold_m + p_.inlier_threshold_z2 * z * z;
	}

	/** r = R p_cur + t - p_prev and J = dr/d(dtheta, dt) with the right
	 * perturbation R <- R Exp(dtheta), t <- t + dt (3x6). */
	static void pointResidual(const Eigen::Matrix3d& R,
	                          const Eigen::Vector3d& t, const Correspondence& c,
	                          Eigen::Vector3d& r,
	                          Eigen::Matrix<double, 3, 6>* J = nullptr);
	/** r = Log(R_prior^T R) and J = dr/d(dtheta) (3x3, right perturbation). */
	static void rotationPriorResidual(const Eigen::Matrix3d& R,
	                                  const Eigen::Matrix3d& R_prior,
	                                  Eigen::Vector3d& r,
	                                  Eigen::Matrix3d* J = nullptr);
	/** Weighted Horn/Kabsch: R, t minimising sum w |p_prev - R p_cur - t|^2
	 * over the selected indices. false if degenerate. */
	static bool kabsch(const std::vector<Correspondence>& c,
	                   const std::vector<int>& idx,
	                   const std::vector<double>& w, Eigen::Matrix3d& R,
	                   Eigen::Vector3d& t);

	/** Refines \a init by minimising robust (Huber) reprojection errors
	 * of its inliers in both directions: p_prev into the current image and
	 * p_cur into the previous one. Depth noise, which dominates the 3D
	 * residuals, moves a point almost only along its ray, so it hardly
	 * changes these pixel errors: the estimate is much less noisy than the
	 * 3D fit. \param optimizeRotation false keeps R (the IMU's) fixed.
	 * Inliers become those within reprojection_threshold_px both ways. */
	MotionEstimate refineReprojection(const std::vector<Correspondence>& c,
	                                  const MotionEstimate& init,
	                                  const Eigen::Matrix3d& K,
	                                  bool optimizeRotation) const;

	/** Forward and backward reprojection residuals (4) and their Jacobian
	 * w.r.t. (dtheta, dt) (4x6, right perturbation R <- R Exp(dtheta)). */
	static void reprojectionResidual(const Eigen::Matrix3d& R,
	                                 const Eigen::Vector3d& t,
	                                 const Eigen::Matrix3d& K,
	                                 const Correspondence& c,
	                                 Eigen::Vector4d& r,
	                                 Eigen::Matrix<double, 4, 6>* J = nullptr);

	const TranslationParams& params() const { return p_; }

 private:
	void scoreInliers(const std::vector<Correspondence>& c,
	                  MotionEstimate& m) const;
	TranslationParams p_;
};

}  // namespace bims::ego
