#include <bims/common/so3.h>

#include <Eigen/SVD>

namespace bims
{
Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& M)
{
	Eigen::JacobiSVD<Eigen::Matrix3d> svd(
	    M, Eigen::ComputeFullU | Eigen::ComputeFullV);
	Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
	if (R.determinant() < 0)
	{
		Eigen::Matrix3d U = svd.matrixU();
		U.col(2) *= -1;
		R = U * svd.matrixV().transpose();
	}
	return R;
}

}  // namespace bims
