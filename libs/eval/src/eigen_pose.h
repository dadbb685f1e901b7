// CPose3D <-> Eigen conversions (internal).
#pragma once

#include <mrpt/math/CMatrixFixed.h>
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Geometry>

namespace bims::eval::detail
{
inline Eigen::Isometry3d toIso(const mrpt::poses::CPose3D& p)
{
	Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
	T.linear() = p.getRotationMatrix().asEigen();
	T.translation() = Eigen::Vector3d(p.x(), p.y(), p.z());
	return T;
}
inline mrpt::poses::CPose3D fromIso(const Eigen::Isometry3d& T)
{
	return mrpt::poses::CPose3D(mrpt::math::CMatrixDouble44(T.matrix()));
}
}  // namespace bims::eval::detail
