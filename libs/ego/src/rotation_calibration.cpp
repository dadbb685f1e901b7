#include <bims/common/so3.h>
#include <bims/ego/rotation_calibration.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include <cmath>
#include <limits>
#include <random>

namespace bims::ego
{
namespace
{
// R maximising sum w a_i . R b_i (no centroid: vectors, not points).
Eigen::Matrix3d procrustes(const std::vector<Eigen::Vector3d>& a,
                           const std::vector<Eigen::Vector3d>& b,
                           const std::vector<int>& idx, double* cond = nullptr)
{
	Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
	for (int i : idx) H += b[i] * a[i].transpose();
	Eigen::JacobiSVD<Eigen::Matrix3d> svd(
	    H, Eigen::ComputeFullU | Eigen::ComputeFullV);
	if (cond)
	{
		const auto s = svd.singularValues();
		*cond = s(0) > 0 ? s(1) / s(0) : 0;
	}
	Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
	if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0)
		D(2, 2) = -1;
	return svd.matrixV() * D * svd.matrixU().transpose();
}
}  // namespace

RotationCalibResult estimateRotationIC(const std::vector<RotationPair>& pairs,
                                       double minAngle_deg,
                                       double inlierThr_deg, unsigned seed)
{
	RotationCalibResult res;
	const double minA = minAngle_deg * M_PI / 180;
	const double thr = inlierThr_deg * M_PI / 180;
	std::vector<Eigen::Vector3d> a, b;
	for (const auto& p : pairs)
	{
		const Eigen::Vector3d wi = logSO3(p.R_IprevI);
		const Eigen::Vector3d wc = logSO3(p.R_CprevC);
		if (!wi.allFinite() || !wc.allFinite()) continue;
		if (wi.norm() < minA || wc.norm() < minA) continue;
		a.push_back(wi);
		b.push_back(wc);
	}
	const int n = static_cast<int>(a.size());
	res.informative = n;
	if (n < 3) return res;

	const auto inliersOf = [&](const Eigen::Matrix3d& R)
	{
		std::vector<int> in;
		for (int i = 0; i < n; i++)
			if ((a[i] - R * b[i]).norm() < thr) in.push_back(i);
		return in;
	};
	std::mt19937 rng(seed);
	std::uniform_int_distribution<int> pick(0, n - 1);
	std::vector<int> best;
	for (int it = 0; it < 300; it++)
	{
		const int i = pick(rng), j = pick(rng);
		if (i == j) continue;
		if (b[i].normalized().cross(b[j].normalized()).norm() < 0.2) continue;
		auto in = inliersOf(procrustes(a, b, {i, j}));
		if (in.size() > best.size()) best = std::move(in);
	}
	if (best.size() < 3) return res;
	Eigen::Matrix3d R = procrustes(a, b, best);
	for (int k = 0; k < 3; k++)
	{
		auto in = inliersOf(R);
		if (in.size() < 3) break;
		R = procrustes(a, b, in, &res.conditioning);
		best = std::move(in);
	}
	double ss = 0;
	for (int i : best) ss += (a[i] - R * b[i]).squaredNorm();
	res.R_IC = R;
	res.inliers = static_cast<int>(best.size());
	res.rms_deg = std::sqrt(ss / best.size()) * 180 / M_PI;
	// the uncertainty of a small rotation delta of R_IC (R <- Exp(delta) R):
	// a_i - Exp(delta) R b_i ~ r_i + [R b_i]_x delta
	Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
	for (int i : best)
	{
		const Eigen::Matrix3d J = skew(R * b[i]);
		info += J.transpose() * J;
	}
	const double dof = std::max(1.0, 3.0 * best.size() - 3);
	const double sigma2 = ss / dof;
	Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(info);
	const double lmin = eig.eigenvalues()(0);  // ascending
	res.uncertainty_deg = lmin > 0 ? std::sqrt(sigma2 / lmin) * 180 / M_PI
	                               : std::numeric_limits<double>::infinity();
	res.weakAxis_I = eig.eigenvectors().col(0);
	res.ok = res.inliers >= 3 && res.conditioning > 0.05;
	return res;
}

std::optional<Eigen::Matrix3d> integrateGyro(const std::deque<ImuSample>& s,
                                             double t0, double t1,
                                             double maxGap_s)
{
	if (s.size() < 2 || !(t1 > t0) || s.front().t > t0 || s.back().t < t1)
		return std::nullopt;
	// Rate at time t, linear between samples.
	const auto rate = [&](size_t i, double t)
	{
		const double u = (t - s[i].t) / (s[i + 1].t - s[i].t);
		return Eigen::Vector3d((1 - u) * s[i].gyro + u * s[i + 1].gyro);
	};
	Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
	for (size_t i = 0; i + 1 < s.size(); i++)
	{
		const double a = std::max(t0, s[i].t), b = std::min(t1, s[i + 1].t);
		if (b <= a) continue;
		if (s[i + 1].t - s[i].t > maxGap_s || !s[i].hasGyro ||
		    !s[i + 1].hasGyro)
			return std::nullopt;
		R = R * expSO3(0.5 * (rate(i, a) + rate(i, b)) * (b - a));
	}
	return orthonormalize(R);
}

}  // namespace bims::ego
