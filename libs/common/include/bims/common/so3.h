// Small SO(3) helpers (exponential/logarithm maps and their Jacobians) used by
// the attitude filter, the translation estimator, the R_IC calibration and
// the sensor rig's [calibration] (its R_IC re-orthonormalised).
// Rotation vectors are in radians; Exp(w) is the rotation by |w| about w/|w|.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>

namespace bims
{
/** [w]x: the skew-symmetric matrix with [w]x v = w x v. */
inline Eigen::Matrix3d skew(const Eigen::Vector3d& w)
{
	Eigen::Matrix3d S;
	S << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
	return S;
}

/** Exp: rotation vector [rad] -> rotation matrix (Rodrigues). */
inline Eigen::Matrix3d expSO3(const Eigen::Vector3d& w)
{
	const double th = w.norm();
	if (th < 1e-12) return Eigen::Matrix3d::Identity() + skew(w);
	return Eigen::AngleAxisd(th, w / th).toRotationMatrix();
}

/** Log: rotation matrix -> rotation vector [rad], angle in [0, pi]. */
inline Eigen::Vector3d logSO3(const Eigen::Matrix3d& R)
{
	const Eigen::AngleAxisd aa(R);
	return aa.angle() * aa.axis();
}

/** Angle of a rotation matrix [rad], robust near 0 and pi. */
inline double angleSO3(const Eigen::Matrix3d& R)
{
	return logSO3(R).norm();
}

/** Right Jacobian of SO(3): Exp(w + d) ~= Exp(w) Exp(Jr(w) d). */
inline Eigen::Matrix3d rightJacobianSO3(const Eigen::Vector3d& w)
{
	const double th = w.norm();
	const Eigen::Matrix3d W = skew(w);
	if (th < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * W;
	const double th2 = th * th;
	return Eigen::Matrix3d::Identity() - (1 - std::cos(th)) / th2 * W +
	       (th - std::sin(th)) / (th2 * th) * W * W;
}

/** Inverse right Jacobian: Log(Exp(w) Exp(d)) ~= w + JrInv(w) d. */
inline Eigen::Matrix3d rightJacobianInvSO3(const Eigen::Vector3d& w)
{
	const double th = w.norm();
	const Eigen::Matrix3d W = skew(w);
	if (th < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * W;
	const double th2 = th * th;
	return Eigen::Matrix3d::Identity() + 0.5 * W +
	       (1 / th2 - (1 + std::cos(th)) / (2 * th * std::sin(th))) * W * W;
}

/** Projects a near-rotation matrix onto SO(3) (SVD). */
Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& M);

}  // namespace bims
