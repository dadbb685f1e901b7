#include <bims/common/so3.h>
#include <bims/ego/translation_estimator.h>

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace bims::ego
{
TranslationEstimator::TranslationEstimator(const TranslationParams& p) : p_(p)
{
}

void TranslationEstimator::pointResidual(const Eigen::Matrix3d& R,
                                         const Eigen::Vector3d& t,
                                         const Correspondence& c,
                                         Eigen::Vector3d& r,
                                         Eigen::Matrix<double, 3, 6>* J)
{
	r = R * c.p_cur + t - c.p_prev;
	if (J)
	{
		J->leftCols<3>() = -R * skew(c.p_cur);
		J->rightCols<3>().setIdentity();
	}
}

void TranslationEstimator::rotationPriorResidual(const Eigen::Matrix3d& R,
                                                 const Eigen::Matrix3d& R_prior,
                                                 Eigen::Vector3d& r,
                                                 Eigen::Matrix3d* J)
{
	r = logSO3(R_prior.transpose() * R);
	if (J) *J = rightJacobianInvSO3(r);
}

bool TranslationEstimator::kabsch(const std::vector<Correspondence>& c,
                                  const std::vector<int>& idx,
                                  const std::vector<double>& w,
                                  Eigen::Matrix3d& R, Eigen::Vector3d& t)
{
	if (idx.size() < 3) return false;
	double sw = 0;
	Eigen::Vector3d mp = Eigen::Vector3d::Zero(), mc = mp;
	for (size_t k = 0; k < idx.size(); k++)
	{
		const double wk = w.empty() ? 1.0 : w[k];
		sw += wk;
		mp += wk * c[idx[k]].p_prev;
		mc += wk * c[idx[k]].p_cur;
	}
	if (sw <= 0) return false;
	mp /= sw;
	mc /= sw;
	Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
	for (size_t k = 0; k < idx.size(); k++)
	{
		const double wk = w.empty() ? 1.0 : w[k];
		H += wk * (c[idx[k]].p_cur - mc) * (c[idx[k]].p_prev - mp).transpose();
	}
	Eigen::JacobiSVD<Eigen::Matrix3d> svd(
	    H, Eigen::ComputeFullU | Eigen::ComputeFullV);
	const Eigen::Vector3d sv = svd.singularValues();
	if (sv(1) < 1e-9 * std::max(1.0, sv(0))) return false;  // collinear
	Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
	if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0)
		D(2, 2) = -1;
	R = svd.matrixV() * D * svd.matrixU().transpose();
	t = mp - R * mc;
	return true;
}

void TranslationEstimator::scoreInliers(const std::vector<Correspondence>& c,
                                        MotionEstimate& m) const
{
	m.inlier.assign(c.size(), 0);
	m.inliers = 0;
	double ss = 0;
	for (size_t i = 0; i < c.size(); i++)
	{
		const double e =
		    (c[i].p_prev - m.R_CprevC * c[i].p_cur - m.t_CprevC).norm();
		if (e < threshold(c[i].p_prev.z()))
		{
			m.inlier[i] = 1;
			++m.inliers;
			ss += e * e;
		}
	}
	m.residual_rms_m = m.inliers ? std::sqrt(ss / m.inliers) : 0;
	m.ok = m.inliers >= p_.min_inliers;
}

MotionEstimate TranslationEstimator::estimateTranslation(
    const std::vector<Correspondence>& c, const Eigen::Matrix3d& R_CprevC) const
{
	MotionEstimate m;
	m.R_CprevC = R_CprevC;
	const size_t n = c.size();
	if (n == 0)
	{
		m.inlier.clear();
		return m;
	}
	// d_i = p_prev - R p_cur: equal to t for every static point.
	std::vector<Eigen::Vector3d> d(n);
	std::vector<double> thr(n);
	for (size_t i = 0; i < n; i++)
	{
		d[i] = c[i].p_prev - R_CprevC * c[i].p_cur;
		thr[i] = threshold(c[i].p_prev.z());
	}
	// Hypotheses: every point when few, else a seeded random subset.
	std::vector<size_t> hyp(n);
	for (size_t i = 0; i < n; i++) hyp[i] = i;
	if (n > static_cast<size_t>(p_.iterations))
	{
		std::mt19937 rng(p_.seed);
		std::shuffle(hyp.begin(), hyp.end(), rng);
		hyp.resize(p_.iterations);
	}
	const bool lmeds = p_.method == RobustMethod::Lmeds;
	double bestCost = std::numeric_limits<double>::infinity();
	Eigen::Vector3d best = d[hyp[0]];
	std::vector<double> e2(n);
	for (size_t h : hyp)
	{
		double cost = 0;
		if (lmeds)
		{
			for (size_t i = 0; i < n; i++) e2[i] = (d[i] - d[h]).squaredNorm();
			std::nth_element(e2.begin(), e2.begin() + n / 2, e2.end());
			cost = e2[n / 2];
		}
		else  // MSAC: truncated quadratic cost, normalised per point
			for (size_t i = 0; i < n; i++)
				cost += std::min(
				    (d[i] - d[h]).squaredNorm() / (thr[i] * thr[i]), 1.0);
		if (cost < bestCost)
		{
			bestCost = cost;
			best = d[h];
		}
	}
	// Least squares over the inliers (weights 1/threshold^2), twice.
	m.t_CprevC = best;
	for (int it = 0; it < 3; it++)
	{
		Eigen::Vector3d s = Eigen::Vector3d::Zero();
		double sw = 0;
		for (size_t i = 0; i < n; i++)
			if ((d[i] - m.t_CprevC).norm() < thr[i])
			{
				const double w = 1 / (thr[i] * thr[i]);
				s += w * d[i];
				sw += w;
			}
		if (sw > 0) m.t_CprevC = s / sw;
	}
	scoreInliers(c, m);
	return m;
}

MotionEstimate TranslationEstimator::estimateSE3(
    const std::vector<Correspondence>& c) const
{
	MotionEstimate m;
	const size_t n = c.size();
	if (n < 3)
	{
		m.inlier.assign(n, 0);
		return m;
	}
	std::mt19937 rng(p_.seed);
	std::uniform_int_distribution<size_t> pick(0, n - 1);
	double bestCost = std::numeric_limits<double>::infinity();
	Eigen::Matrix3d bestR = Eigen::Matrix3d::Identity();
	Eigen::Vector3d bestT = Eigen::Vector3d::Zero();
	std::vector<double> thr2(n);
	for (size_t i = 0; i < n; i++)
		thr2[i] = std::pow(threshold(c[i].p_prev.z()), 2);
	for (int it = 0; it < p_.vision_iterations; it++)
	{
		const size_t a = pick(rng), b = pick(rng), d = pick(rng);
		if (a == b || b == d || a == d) continue;
		// Reject near-degenerate triples (small triangle) and triples whose
		// pairwise distances disagree (not a rigid motion).
		const Eigen::Vector3d u = c[b].p_prev - c[a].p_prev;
		const Eigen::Vector3d v = c[d].p_prev - c[a].p_prev;
		if (u.cross(v).norm() < 1e-4) continue;
		const auto rigid = [&](size_t i, size_t j)
		{
			const double dp = (c[i].p_prev - c[j].p_prev).norm();
			const double dc = (c[i].p_cur - c[j].p_cur).norm();
			return std::abs(dp - dc) < std::sqrt(thr2[i]) + std::sqrt(thr2[j]);
		};
		if (!rigid(a, b) || !rigid(b, d) || !rigid(a, d)) continue;
		Eigen::Matrix3d R;
		Eigen::Vector3d t;
		if (!kabsch(c, {int(a), int(b), int(d)}, {}, R, t)) continue;
		double cost = 0;
		for (size_t i = 0; i < n && cost < bestCost; i++)
			cost += std::min(
			    (c[i].p_prev - R * c[i].p_cur - t).squaredNorm() / thr2[i],
			    1.0);
		if (cost < bestCost)
		{
			bestCost = cost;
			bestR = R;
			bestT = t;
		}
	}
	if (!std::isfinite(bestCost))  // no non-degenerate rigid triple
	{
		m.inlier.assign(n, 0);
		return m;
	}
	m.R_CprevC = bestR;
	m.t_CprevC = bestT;
	for (int it = 0; it < 3; it++)
	{
		scoreInliers(c, m);
		std::vector<int> idx;
		std::vector<double> w;
		for (size_t i = 0; i < n; i++)
			if (m.inlier[i])
			{
				idx.push_back(static_cast<int>(i));
				w.push_back(1 / thr2[i]);
			}
		Eigen::Matrix3d R;
		Eigen::Vector3d t;
		if (!kabsch(c, idx, w, R, t)) break;
		m.R_CprevC = R;
		m.t_CprevC = t;
	}
	scoreInliers(c, m);
	return m;
}

MotionEstimate TranslationEstimator::refineSE3(
    const std::vector<Correspondence>& c, const MotionEstimate& init,
    const Eigen::Matrix3d& R_prior, double sigmaPrior_rad) const
{
	MotionEstimate m = init;
	if (init.inlier.size() != c.size() || init.inliers < 3) return m;
	Eigen::Matrix3d R = init.R_CprevC;
	Eigen::Vector3d t = init.t_CprevC;
	const double wp = 1 / (sigmaPrior_rad * sigmaPrior_rad);
	for (int it = 0; it < 6; it++)
	{
		Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
		Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
		for (size_t i = 0; i < c.size(); i++)
		{
			if (!init.inlier[i]) continue;
			Eigen::Vector3d r;
			Eigen::Matrix<double, 3, 6> J;
			pointResidual(R, t, c[i], r, &J);
			const double z = std::max(c[i].p_prev.z(), 1.0);
			const double s = p_.point_sigma_m * z * z;
			const double e = r.norm() / s;
			const double huber = e < 1.345 ? 1.0 : 1.345 / e;
			const double w = huber / (s * s);
			A += w * J.transpose() * J;
			g += w * J.transpose() * r;
		}
		Eigen::Vector3d rp;
		Eigen::Matrix3d Jp;
		rotationPriorResidual(R, R_prior, rp, &Jp);
		A.topLeftCorner<3, 3>() += wp * Jp.transpose() * Jp;
		g.head<3>() += wp * Jp.transpose() * rp;
		const Eigen::Matrix<double, 6, 1> dx = -A.ldlt().solve(g);
		if (!dx.allFinite()) break;
		R = orthonormalize(R * expSO3(dx.head<3>()));
		t += dx.tail<3>();
		if (dx.norm() < 1e-10) break;
	}
	m.R_CprevC = R;
	m.t_CprevC = t;
	scoreInliers(c, m);
	return m;
}

void TranslationEstimator::reprojectionResidual(const Eigen::Matrix3d& R,
                                                const Eigen::Vector3d& t,
                                                const Eigen::Matrix3d& K,
                                                const Correspondence& c,
                                                Eigen::Vector4d& r,
                                                Eigen::Matrix<double, 4, 6>* J)
{
	const auto proj = [&](const Eigen::Vector3d& q, Eigen::Vector2d& x,
	                      Eigen::Matrix<double, 2, 3>& Jp)
	{
		const double iz = 1.0 / q.z();
		x << K(0, 0) * q.x() * iz + K(0, 2), K(1, 1) * q.y() * iz + K(1, 2);
		Jp << K(0, 0) * iz, 0, -K(0, 0) * q.x() * iz * iz, 0, K(1, 1) * iz,
		    -K(1, 1) * q.y() * iz * iz;
	};
	// Forward: previous point seen from the current camera.
	const Eigen::Vector3d q = R.transpose() * (c.p_prev - t);
	// Backward: current point seen from the previous camera.
	const Eigen::Vector3d sp = R * c.p_cur + t;
	Eigen::Vector2d xf, xb;
	Eigen::Matrix<double, 2, 3> Jf, Jb;
	proj(q, xf, Jf);
	proj(sp, xb, Jb);
	r.head<2>() = xf - c.x_cur;
	r.tail<2>() = xb - c.x_prev;
	if (J)
	{
		J->block<2, 3>(0, 0) = Jf * skew(q);
		J->block<2, 3>(0, 3) = -Jf * R.transpose();
		J->block<2, 3>(2, 0) = -Jb * R * skew(c.p_cur);
		J->block<2, 3>(2, 3) = Jb;
	}
}

MotionEstimate TranslationEstimator::refineReprojection(
    const std::vector<Correspondence>& c, const MotionEstimate& init,
    const Eigen::Matrix3d& K, bool optimizeRotation) const
{
	MotionEstimate m = init;
	if (init.inlier.size() != c.size() || init.inliers < 3) return m;
	Eigen::Matrix3d R = init.R_CprevC;
	Eigen::Vector3d t = init.t_CprevC;
	const double sig = p_.reprojection_sigma_px, k = 1.345;
	for (int it = 0; it < 5; it++)
	{
		Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
		Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
		for (size_t i = 0; i < c.size(); i++)
		{
			if (!init.inlier[i]) continue;
			Eigen::Vector4d r;
			Eigen::Matrix<double, 4, 6> J;
			reprojectionResidual(R, t, K, c[i], r, &J);
			if (!r.allFinite()) continue;
			for (int h = 0; h < 2; h++)
			{
				const auto rh = r.segment<2>(2 * h);
				const auto Jh = J.block<2, 6>(2 * h, 0);
				const double e = rh.norm() / sig;
				const double w = (e < k ? 1.0 : k / e) / (sig * sig);
				A += w * Jh.transpose() * Jh;
				g += w * Jh.transpose() * rh;
			}
		}
		Eigen::Matrix<double, 6, 1> dx = Eigen::Matrix<double, 6, 1>::Zero();
		if (optimizeRotation)
			dx = -A.ldlt().solve(g);
		else
			dx.tail<3>() =
			    -A.bottomRightCorner<3, 3>().ldlt().solve(g.tail<3>());
		if (!dx.allFinite()) return m;  // keep the 3D estimate
		R = orthonormalize(R * expSO3(dx.head<3>()));
		t += dx.tail<3>();
		if (dx.norm() < 1e-9) break;
	}
	m.R_CprevC = R;
	m.t_CprevC = t;
	// Inliers: consistent in 3D (as before) and in both images.
	m.inliers = 0;
	double ss = 0;
	const double thr = p_.reprojection_threshold_px;
	for (size_t i = 0; i < c.size(); i++)
	{
		if (!init.inlier[i]) continue;
		Eigen::Vector4d r;
		reprojectionResidual(R, t, K, c[i], r);
		const bool in = r.allFinite() && r.head<2>().norm() < thr &&
		                r.tail<2>().norm() < thr;
		m.inlier[i] = in ? 1 : 0;
		if (in)
		{
			++m.inliers;
			ss += (c[i].p_prev - R * c[i].p_cur - t).squaredNorm();
		}
	}
	m.residual_rms_m = m.inliers ? std::sqrt(ss / m.inliers) : 0;
	m.ok = m.inliers >= p_.min_inliers;
	return m;
}

}  // namespace bims::ego
