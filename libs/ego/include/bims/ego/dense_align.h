// Dense RGB-D alignment of a frame to a reference frame (a keyframe): the
// motion T_RC (current camera in the reference camera) that makes the
// current frame's points land on the reference's surfaces (point-to-plane
// ICP with projective association) and its grey values match the reference's
// (photometric term), coarse to fine, with Tukey's biweight on both
// residuals. Content the reference does not hold (a person who walked in, an
// object that moved) lands far from the reference surface: it fails the
// depth gate or gets zero weight, so it does not pull the pose.
//
// The reference's normals and gradients are computed once
// (DenseFrame::prepareReference): a keyframe is reused for many frames.
// Derivation and measurements: docs/ego.md, "Map-anchored tracking".
#pragma once

#include <bims/ego/params.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace bims::ego
{
/** A reference pixel packed for the alignment's lookups (one cache line
 * for two pixels): depth (0 none, -1 dropped as moving), normal, plane
 * offset d = n . P, grey, gradient. */
struct RefPixel
{
	float z, nx, ny, nz, d, g, gx, gy;
};

/** One pyramid level of a frame. */
struct DenseLevel
{
	cv::Mat depth;   ///< CV_32FC1 [m], 0 = none (or excluded)
	cv::Mat grey;    ///< CV_32FC1 grey levels
	cv::Mat gx, gy;  ///< CV_32FC1 grey gradients [grey/px] (reference only)
	cv::Mat normal;  ///< CV_32FC3 unit normals, 0 = none (reference only)
	std::vector<RefPixel> packed;  ///< the same, packed (reference only)
	/** CV_8UC1 non-zero = predicted moving: not sampled for the fit (still
	 * classified in the outlier image), or empty. */
	cv::Mat exclude;
	float fx = 0, fy = 0, cx = 0, cy = 0;  ///< intrinsics of the level [px]
};

/** A frame as a pyramid (level 0 = full size, each level half the last). */
class DenseFrame
{
 public:
	/** Builds levels 0..p.coarsest_level from \a image (CV_8UC1 grey, or empty:
	 * a depth-only frame, aligned without the photometric term) and
	 * \a depth (CV_32FC1 [m]). Depth outside [min, max]_depth_m is dropped;
	 * pixels where \a exclude (CV_8UC1, may be empty) is non-zero are not
	 * sampled when this frame is aligned (DenseLevel::exclude). A
	 * 2x2 block's depth is the mean of its readings when they agree (within
	 * 3 % + 1 cm), else none (no averaging across depth edges). */
	void build(const cv::Mat& image, const cv::Mat& depth,
	           const Eigen::Matrix3d& K, const AnchorParams& p,
	           const cv::Mat& exclude = cv::Mat());
	/** Adds gradients and normals at levels finest..coarsest: the frame
	 * can then be the reference of alignDense(). */
	void prepareReference(const AnchorParams& p);
	bool isReference() const { return reference_; }
	/** Whether it was built with an image (else depth only). */
	bool hasImage() const { return image_; }
	/** Drops the readings where \a mask (CV_8UC1 of the finest level's
	 * size) is non-zero, from the finest and every coarser level: content
	 * known to move (marked so: a point landing there counts as covered
	 * and as an outlier). Call after prepareReference(). */
	void dropReadings(const cv::Mat& mask, const AnchorParams& p);
	bool empty() const { return levels.empty(); }

	std::vector<DenseLevel> levels;

 private:
	bool reference_ = false;
	bool image_ = true;
	cv::Mat noImage_;  // the flat image of a depth-only frame
};

/** Result of one alignment. */
struct DenseAlignResult
{
	bool ok = false;  ///< converged with enough inliers
	std::string why;  ///< why not (empty when ok)
	Eigen::Matrix3d R_RC = Eigen::Matrix3d::Identity();  ///< current in ref
	Eigen::Vector3d t_RC = Eigen::Vector3d::Zero();      ///< [m]
	int points = 0;      ///< sampled points with depth, finest level
	int associated = 0;  ///< of those, landing on a reference reading
	int inliers = 0;     ///< of those, within the gate and Tukey's limit
	/** inliers / the associated points that landed on the reference's
	 * surface (not in front of it, not behind it: those are explained by
	 * motion in the scene). */
	double inlier_fraction = 0;
	double overlap = 0;  ///< inliers / points
	/** associated / points: how much of the frame the reference covers
	 * (occluders count as covered; they are not a reason for a new
	 * keyframe). */
	double coverage = 0;
	int guess = 0;         ///< index of the initial guess that won
	double rms_geo_m = 0;  ///< RMS point-to-plane residual of inliers
	int iterations = 0;    ///< Gauss-Newton steps over all levels
	/** Finest-level image (CV_8UC1): 255 where a current point is an
	 * outlier (in front of the reference's surface or off it: candidate
	 * moving), 0 elsewhere. */
	cv::Mat outliers;
	/** Finest-level image (CV_8UC1): 255 where a current point (excluded
	 * ones too) lies on the reference's surface within the gate and Tukey's
	 * limit: it agrees with the static scene. */
	cv::Mat consistent;
	/** The normal equations of the data alone (no prior) at the result,
	 * finest level: H = sum w J^T J over the increment (v, w) of T_RC
	 * (translation first, reference frame), residuals in their noise's
	 * units: the information the frame's depth (and image) gives about its
	 * pose [1/m^2, 1/(m rad), 1/rad^2]. */
	Eigen::Matrix<double, 6, 6> information =
	    Eigen::Matrix<double, 6, 6>::Zero();
	/** Reference pixels (finest level, v * width + u) that a current point
	 * lies behind by more than the gate: the reference's surface there has
	 * moved away (a static surface is never seen through). */
	std::vector<int> seenThrough;
};

/** An initial guess of T_RC. */
struct InitialGuess
{
	Eigen::Matrix3d R;
	Eigen::Vector3d t;
};

/** A Gaussian prior on the translation t_RC (e.g. the inertial
 * prediction): mean \a t, information \a info (3x3, reference frame,
 * [1/m^2]). */
struct TranslationPrior
{
	Eigen::Vector3d t = Eigen::Vector3d::Zero();
	Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
};

// The per-point terms of alignDense(), on a current point moved by the pose
// estimate into the reference camera: X = R_RC p + t_RC = (X, Y, Z). The
// Jacobians are w.r.t. the increment (v, w) (translation first, then
// rotation [m, rad]) applied on the left, as the alignment applies it:
// R <- Exp(w) R, t <- Exp(w) t + v, i.e. X <- Exp(w) X + v. Templates on
// the scalar: the alignment runs them in float (tests in double).

/** Pinhole projection (u, v) of X with iz = 1 / Z. */
template <typename T>
inline void denseProject(T X, T Y, T iz, T fx, T fy, T cx, T cy, T& u, T& v)
{
	u = fx * X * iz + cx;
	v = fy * Y * iz + cy;
}

/** Point-to-plane residual n . X - d of the reference plane (n, d). */
template <typename T>
inline T pointToPlaneResidual(T X, T Y, T Z, T nx, T ny, T nz, T d)
{
	return nx * X + ny * Y + nz * Z - d;
}

/** The row of a residual whose gradient w.r.t. the point X is g, w.r.t.
 * the increment (v, w) that moves X to X + v + w x X: [g, X x g]. */
template <typename T>
inline void poseRow(T X, T Y, T Z, T g0, T g1, T g2, T J[6])
{
	J[0] = g0;
	J[1] = g1;
	J[2] = g2;
	J[3] = Y * g2 - Z * g1;
	J[4] = Z * g0 - X * g2;
	J[5] = X * g1 - Y * g0;
}

/** Its Jacobian w.r.t. (v, w): [n, X x n]. */
template <typename T>
inline void pointToPlaneJacobian(T X, T Y, T Z, T nx, T ny, T nz, T J[6])
{
	poseRow(X, Y, Z, nx, ny, nz, J);
}

/** Jacobian w.r.t. (v, w) of the photometric residual I(u, v) - grey (grey
 * and the brightness offset fixed), with (u, v) = denseProject(X) and
 * (gx, gy) the reference's gradient of I there [grey/px] (the alignment
 * interpolates its Sobel gradients), iz = 1 / Z:
 * g = dI/dX = (gx fx iz, gy fy iz, -(gx fx X + gy fy Y) iz^2),
 * J = [g, X x g]. */
template <typename T>
inline void photometricJacobian(T X, T Y, T Z, T iz, T gx, T gy, T fx, T fy,
                                T J[6])
{
	const T g0 = gx * fx * iz, g1 = gy * fy * iz,
	        g2 = -(gx * fx * X + gy * fy * Y) * iz * iz;
	poseRow(X, Y, Z, g0, g1, g2, J);
}

/** Aligns \a cur to \a ref (ref.isReference()) from the initial guess
 * (R_init, t_init) = T_RC. \param R_prior optional prior on R_RC with
 * std. dev. \a sigmaPrior_rad (the IMU's rotation); sigmaPrior_rad = 0
 * holds the rotation at R_prior and estimates the translation only.
 * \param tPrior optional prior on t_RC (the IMU's prediction): the
 * result is the most probable pose given the data and both priors. */
DenseAlignResult alignDense(const DenseFrame& ref, const DenseFrame& cur,
                            const Eigen::Matrix3d& R_init,
                            const Eigen::Vector3d& t_init,
                            const AnchorParams& p,
                            const Eigen::Matrix3d* R_prior = nullptr,
                            double sigmaPrior_rad = 0,
                            const TranslationPrior* tPrior = nullptr);

/** Same, from several initial guesses (the photometric term only when both
 * frames have an image): each is iterated at the coarsest
 * level (a later one only if it starts with more inliers than the first),
 * the one with most inliers there goes on to the finer levels (e.g. the
 * frame-to-frame estimate, which people in view can corrupt, and the
 * constant-velocity prediction). */
DenseAlignResult alignDense(const DenseFrame& ref, const DenseFrame& cur,
                            const std::vector<InitialGuess>& inits,
                            const AnchorParams& p,
                            const Eigen::Matrix3d* R_prior = nullptr,
                            double sigmaPrior_rad = 0,
                            const TranslationPrior* tPrior = nullptr);

/** The information the data give about the translation alone (3x3, the
 * reference frame [1/m^2]): the translation block of \a H with the
 * rotation marginalised out (Schur complement), the rotation's prior
 * information \a rotationPriorInfo [1/rad^2] added to its block first (a
 * rotation held fixed: pass infinity). */
Eigen::Matrix3d translationInformation(const Eigen::Matrix<double, 6, 6>& H,
                                       double rotationPriorInfo);

}  // namespace bims::ego
