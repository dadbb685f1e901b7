#include <bims/eval/pose_utils.h>

#include <Eigen/SVD>
#include <algorithm>

#include "eigen_pose.h"

namespace bims::eval
{
using detail::fromIso;
using detail::toIso;

std::optional<mrpt::poses::CPose3D> interpolatePose(const Trajectory& traj,
                                                    double t, double maxGap)
{
	if (traj.empty() || t < traj.front().t || t > traj.back().t)
		return std::nullopt;
	const auto it = std::lower_bound(traj.begin(), traj.end(), t,
	                                 [](const StampedPose& p, double s)
	                                 { return p.t < s; });
	if (it->t == t) return it->T_WC;
	const auto& b = *it;
	const auto& a = *(it - 1);
	if (b.t - a.t > maxGap) return std::nullopt;
	const double s = (t - a.t) / (b.t - a.t);
	const Eigen::Isometry3d Ta = toIso(a.T_WC), Tb = toIso(b.T_WC);
	const Eigen::Quaterniond qa(Ta.linear()), qb(Tb.linear());
	Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
	T.linear() = qa.slerp(s, qb).toRotationMatrix();
	T.translation() = (1 - s) * Ta.translation() + s * Tb.translation();
	return fromIso(T);
}

const double* bonnTm4x4()
{
	static const double m[16] = {1.0157,  0.1828,  -0.2389, 0.0113,   //
	                             0.0009,  -0.8431, -0.6413, -0.0098,  //
	                             -0.3009, 0.6147,  -0.8085, 0.0111,   //
	                             0,       0,       0,       1};
	return m;
}

namespace
{
Eigen::Isometry3d bonnTm()
{
	const Eigen::Matrix4d M =
	    Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(
	        bonnTm4x4());
	const Eigen::Matrix3d A = M.block<3, 3>(0, 0);
	Eigen::JacobiSVD<Eigen::Matrix3d> svd(
	    A, Eigen::ComputeFullU | Eigen::ComputeFullV);
	Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
	if (R.determinant() < 0)
	{
		Eigen::Matrix3d U = svd.matrixU();
		U.col(2) *= -1;
		R = U * svd.matrixV().transpose();
	}
	Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
	T.linear() = R;
	T.translation() = M.block<3, 1>(0, 3);
	return T;
}
Eigen::Isometry3d bonnTros()
{
	Eigen::Matrix3d R;
	R << -1, 0, 0, 0, 0, 1, 0, 1, 0;
	Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
	T.linear() = R;
	return T;
}
}  // namespace

mrpt::poses::CPose3D bonnMarkerToCamera(const mrpt::poses::CPose3D& T_gt)
{
	static const Eigen::Isometry3d Tm = bonnTm(), Tros = bonnTros();
	// Bonn's T_ros * T_gt * T_ros * T_m, without the leftmost T_ros: that
	// factor only re-expresses the world in a y-up basis; we keep the z-up
	// motion-capture world (the project's {W} convention).
	return fromIso(toIso(T_gt) * Tros * Tm);
}

}  // namespace bims::eval
