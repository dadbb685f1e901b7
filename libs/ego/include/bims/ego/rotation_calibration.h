// Estimation of the IMU-camera rotation R_IC ({C} in {I}, p_I = R_IC p_C)
// from a sequence: the rotation the gyro measures between two frames,
// R_IprevI, and the one vision measures, R_CprevC, are conjugate,
// R_IprevI = R_IC R_CprevC R_IC^T, so their rotation vectors satisfy
// Log(R_IprevI) = R_IC Log(R_CprevC) (the hand-eye rotation problem).
// R_IC is the orthogonal Procrustes (Wahba) solution over all pairs, made
// robust by 2-pair RANSAC (pairs with tracking failures are outliers).
#pragma once

#include <bims/ego/attitude_filter.h>

#include <Eigen/Core>

#include <deque>
#include <optional>
#include <vector>

namespace bims::ego
{
/** Relative rotations of one frame interval. */
struct RotationPair
{
	Eigen::Matrix3d R_IprevI;  ///< integrated gyro
	Eigen::Matrix3d R_CprevC;  ///< visual odometry
};

struct RotationCalibResult
{
	bool ok = false;  ///< enough informative inlier pairs, non-degenerate
	Eigen::Matrix3d R_IC = Eigen::Matrix3d::Identity();
	int informative = 0;  ///< pairs rotating more than minAngle
	int inliers = 0;
	double rms_deg = 0;  ///< RMS of |Log_I - R_IC Log_C| over inliers [deg]
	/** Ratio of the 2nd to 1st singular value of the data: near 0 means the
	 * motion rotated about one axis only and R_IC is not observable. */
	double conditioning = 0;
	/** 1-sigma uncertainty of R_IC about its worst-determined axis [deg]:
	 * the covariance sigma^2 (sum_i J_i^T J_i)^-1 of a small rotation of
	 * R_IC, J_i = [R_IC Log_C,i]_x, sigma^2 the residuals' variance per
	 * component. Rotations about one axis only leave the rotation of R_IC
	 * about that axis unobserved: this grows without bound. */
	double uncertainty_deg = 0;
	/** That axis, a unit vector in {I}. */
	Eigen::Vector3d weakAxis_I = Eigen::Vector3d::UnitX();
};

/** \param minAngle_deg pairs rotating less (either sensor) are skipped.
 * \param inlierThr_deg residual limit for a pair to count as inlier. */
RotationCalibResult estimateRotationIC(const std::vector<RotationPair>& pairs,
                                       double minAngle_deg = 0.5,
                                       double inlierThr_deg = 0.5,
                                       unsigned seed = 1);

/** R_I(t0)I(t1): the raw gyro integrated (trapezoidal) from t0 to t1 [s, IMU
 * clock] over \a samples (sorted by time). nullopt if the samples do not
 * cover [t0, t1] or a gap exceeds maxGap_s. */
std::optional<Eigen::Matrix3d> integrateGyro(
    const std::deque<ImuSample>& samples, double t0, double t1,
    double maxGap_s = 0.1);

}  // namespace bims::ego
