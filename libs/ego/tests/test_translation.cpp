// TranslationEstimator: robustness to 40 % outliers (features on moving
// objects), vision-only SE(3), analytic vs numeric Jacobians, bad input.
#include <bims/common/so3.h>
#include <bims/ego/translation_estimator.h>
#include <gtest/gtest.h>

#include <random>

using namespace bims;  // so3.h
using namespace bims::ego;

namespace
{
struct Data
{
	std::vector<Correspondence> c;
	std::vector<bool> outlier;
};
// Static points seen before/after the motion (R, t) with depth noise, plus
// a fraction of points on two objects moving on their own.
Data makeData(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, int n,
              double outlierFrac, uint32_t seed)
{
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> U(-1, 1), Z(0.8, 5);
	std::normal_distribution<double> N(0, 1);
	Data d;
	const Eigen::Vector3d obj1(0.25, -0.05, 0.1), obj2(-0.15, 0.0, -0.3);
	for (int i = 0; i < n; i++)
	{
		const double z = Z(rng);
		const Eigen::Vector3d p_prev(U(rng) * 0.6 * z, U(rng) * 0.45 * z, z);
		Eigen::Vector3d p_cur = R.transpose() * (p_prev - t);
		const bool out = i < outlierFrac * n;
		if (out)
			p_cur += (i % 2 ? obj1 : obj2) +
			         0.02 * Eigen::Vector3d(N(rng), N(rng), N(rng));
		const double s = 0.0015 * z * z;  // Kinect-like depth noise
		Correspondence c{p_prev, p_cur};
		c.p_prev += s * Eigen::Vector3d(N(rng), N(rng), N(rng));
		c.p_cur += s * Eigen::Vector3d(N(rng), N(rng), N(rng));
		d.c.push_back(c);
		d.outlier.push_back(out);
	}
	return d;
}
const Eigen::Matrix3d kR = expSO3(Eigen::Vector3d(0.02, -0.05, 0.01));
const Eigen::Vector3d kT(0.04, -0.01, 0.06);
}  // namespace

TEST(TranslationEstimator, RecoversTranslationWith40PercentOutliers)
{
	const Data d = makeData(kR, kT, 200, 0.4, 3);
	for (const char* method : {"ransac", "lmeds"})
	{
		TranslationParams p;
		p.method = bims::parseChoice<RobustMethod>(method);
		const MotionEstimate m =
		    TranslationEstimator(p).estimateTranslation(d.c, kR);
		ASSERT_TRUE(m.ok) << method;
		EXPECT_LT((m.t_CprevC - kT).norm(), 0.004) << method;
		int wrong = 0;
		for (size_t i = 0; i < d.c.size(); i++)
			wrong += (m.inlier[i] && d.outlier[i]);
		EXPECT_LE(wrong, 2)
		    << method;  // a far point moving little is ambiguous
		EXPECT_GT(m.inliers, 105) << method;
		// Plain least squares over all points would be far off.
		Eigen::Vector3d mean = Eigen::Vector3d::Zero();
		for (const auto& c : d.c) mean += c.p_prev - kR * c.p_cur;
		EXPECT_GT((mean / d.c.size() - kT).norm(), 0.03);
	}
}

TEST(TranslationEstimator, VisionOnlySE3With40PercentOutliers)
{
	const Data d = makeData(kR, kT, 200, 0.4, 5);
	const MotionEstimate m = TranslationEstimator().estimateSE3(d.c);
	ASSERT_TRUE(m.ok);
	EXPECT_LT(angleSO3(m.R_CprevC.transpose() * kR) * 180 / M_PI, 0.3);
	EXPECT_LT((m.t_CprevC - kT).norm(), 0.01);
	int wrong = 0;
	for (size_t i = 0; i < d.c.size(); i++)
		wrong += (m.inlier[i] && d.outlier[i]);
	EXPECT_LE(wrong, 3);
}

TEST(TranslationEstimator, PointJacobianMatchesNumeric)
{
	const Eigen::Matrix3d R = expSO3(Eigen::Vector3d(0.3, -0.2, 0.5));
	const Eigen::Vector3d t(0.1, 0.2, -0.3);
	const Correspondence c{{0.4, -0.3, 2.0}, {0.5, 0.1, 1.7}};
	Eigen::Vector3d r0;
	Eigen::Matrix<double, 3, 6> J;
	TranslationEstimator::pointResidual(R, t, c, r0, &J);
	const double h = 1e-6;
	for (int k = 0; k < 6; k++)
	{
		Eigen::Matrix<double, 6, 1> dx = Eigen::Matrix<double, 6, 1>::Zero();
		dx(k) = h;
		Eigen::Vector3d rp, rm;
		TranslationEstimator::pointResidual(R * expSO3(dx.head<3>()),
		                                    t + dx.tail<3>(), c, rp);
		TranslationEstimator::pointResidual(R * expSO3(-dx.head<3>()),
		                                    t - dx.tail<3>(), c, rm);
		const Eigen::Vector3d num = (rp - rm) / (2 * h);
		EXPECT_LT((num - J.col(k)).norm(), 1e-7) << "column " << k;
	}
}

TEST(TranslationEstimator, RotationPriorJacobianMatchesNumeric)
{
	const Eigen::Matrix3d Rp = expSO3(Eigen::Vector3d(0.1, 0.2, -0.1));
	const Eigen::Matrix3d R = Rp * expSO3(Eigen::Vector3d(0.4, -0.7, 0.3));
	Eigen::Vector3d r0;
	Eigen::Matrix3d J;
	TranslationEstimator::rotationPriorResidual(R, Rp, r0, &J);
	const double h = 1e-6;
	for (int k = 0; k < 3; k++)
	{
		Eigen::Vector3d d = Eigen::Vector3d::Zero();
		d(k) = h;
		Eigen::Vector3d rp, rm;
		TranslationEstimator::rotationPriorResidual(R * expSO3(d), Rp, rp);
		TranslationEstimator::rotationPriorResidual(R * expSO3(-d), Rp, rm);
		EXPECT_LT(((rp - rm) / (2 * h) - J.col(k)).norm(), 1e-6) << k;
	}
}

TEST(TranslationEstimator, RefinementFusesImuPrior)
{
	const Data d = makeData(kR, kT, 200, 0.3, 9);
	TranslationEstimator est;
	// A biased IMU rotation (0.5 deg off): a tight prior keeps it, a loose
	// one lets the features correct it.
	const Eigen::Matrix3d Rimu =
	    kR * expSO3(Eigen::Vector3d(0, 0.5 * M_PI / 180, 0));
	const MotionEstimate m0 = est.estimateTranslation(d.c, Rimu);
	ASSERT_TRUE(m0.ok);
	const MotionEstimate tight = est.refineSE3(d.c, m0, Rimu, 1e-5);
	const MotionEstimate loose = est.refineSE3(d.c, m0, Rimu, 1.0);
	const auto deg = [](const Eigen::Matrix3d& A, const Eigen::Matrix3d& B)
	{ return angleSO3(A.transpose() * B) * 180 / M_PI; };
	EXPECT_LT(deg(tight.R_CprevC, Rimu), 0.01);
	EXPECT_LT(deg(loose.R_CprevC, kR), 0.15);
	EXPECT_LT((loose.t_CprevC - kT).norm(), 0.006);
}

TEST(TranslationEstimator, FailsCleanlyOnTooFewPoints)
{
	TranslationEstimator est;
	EXPECT_FALSE(est.estimateTranslation({}, kR).ok);
	const Data d = makeData(kR, kT, 2, 0, 1);
	EXPECT_FALSE(est.estimateSE3(d.c).ok);
	EXPECT_FALSE(est.estimateTranslation(d.c, kR).ok);
	// All points coplanar on a line: degenerate for SE(3).
	std::vector<Correspondence> line;
	for (int i = 0; i < 20; i++)
		line.push_back({{0.1 * i, 0, 2}, {0.1 * i, 0, 2}});
	const MotionEstimate m = est.estimateSE3(line);
	EXPECT_TRUE(m.R_CprevC.allFinite());
	EXPECT_FALSE(m.ok);
}

TEST(TranslationEstimator, ReprojectionJacobianMatchesNumeric)
{
	Eigen::Matrix3d K;
	K << 525, 0, 319.5, 0, 525, 239.5, 0, 0, 1;
	const Eigen::Matrix3d R = expSO3(Eigen::Vector3d(0.05, -0.1, 0.03));
	const Eigen::Vector3d t(0.05, -0.02, 0.08);
	Correspondence c{{0.4, -0.3, 2.5}, {0.5, 0.1, 2.2}};
	c.x_prev = {300, 200};
	c.x_cur = {330, 260};
	Eigen::Vector4d r0;
	Eigen::Matrix<double, 4, 6> J;
	TranslationEstimator::reprojectionResidual(R, t, K, c, r0, &J);
	const double h = 1e-6;
	for (int k = 0; k < 6; k++)
	{
		Eigen::Matrix<double, 6, 1> dx = Eigen::Matrix<double, 6, 1>::Zero();
		dx(k) = h;
		Eigen::Vector4d rp, rm;
		TranslationEstimator::reprojectionResidual(R * expSO3(dx.head<3>()),
		                                           t + dx.tail<3>(), K, c, rp);
		TranslationEstimator::reprojectionResidual(R * expSO3(-dx.head<3>()),
		                                           t - dx.tail<3>(), K, c, rm);
		EXPECT_LT(((rp - rm) / (2 * h) - J.col(k)).norm(), 1e-4)
		    << "column " << k;
	}
}

TEST(TranslationEstimator, ReprojectionRefinementBeatsNoisyDepth)
{
	// Depth noise 1.5e-3 z^2 (Kinect-like), pixels exact to 0.1 px: the
	// reprojection refinement is several times more accurate than the 3D fit.
	Eigen::Matrix3d K;
	K << 525, 0, 319.5, 0, 525, 239.5, 0, 0, 1;
	std::mt19937 rng(21);
	std::normal_distribution<double> N(0, 1);
	std::uniform_real_distribution<double> U(-1, 1), Z(1.5, 4.5);
	double err3d = 0, errRep = 0;
	const Eigen::Matrix3d R = expSO3(Eigen::Vector3d(0.004, -0.006, 0.002));
	const Eigen::Vector3d t(0.004, -0.002, 0.006);
	TranslationEstimator est;
	for (int trial = 0; trial < 20; trial++)
	{
		std::vector<Correspondence> cs;
		for (int i = 0; i < 250; i++)
		{
			const double z = Z(rng);
			const Eigen::Vector3d P(U(rng) * 0.55 * z, U(rng) * 0.4 * z, z);
			const Eigen::Vector3d Pc = R.transpose() * (P - t);
			Correspondence c;
			const Eigen::Vector3d xp = K * P, xc = K * Pc;
			c.x_prev =
			    xp.head<2>() / xp.z() + 0.1 * Eigen::Vector2d(N(rng), N(rng));
			c.x_cur =
			    xc.head<2>() / xc.z() + 0.1 * Eigen::Vector2d(N(rng), N(rng));
			const double zp = P.z() + 1.5e-3 * P.z() * P.z() * N(rng);
			const double zc = Pc.z() + 1.5e-3 * Pc.z() * Pc.z() * N(rng);
			c.p_prev = zp * K.inverse() *
			           Eigen::Vector3d(c.x_prev.x(), c.x_prev.y(), 1);
			c.p_cur =
			    zc * K.inverse() * Eigen::Vector3d(c.x_cur.x(), c.x_cur.y(), 1);
			cs.push_back(c);
		}
		const MotionEstimate m3 = est.estimateTranslation(cs, R);
		const MotionEstimate mr = est.refineReprojection(cs, m3, K, false);
		ASSERT_TRUE(mr.ok);
		err3d += (m3.t_CprevC - t).norm() / 20;
		errRep += (mr.t_CprevC - t).norm() / 20;
	}
	EXPECT_LT(errRep, 0.5 * err3d)
	    << "3D " << err3d << " reprojection " << errRep;
	EXPECT_LT(errRep, 0.001);
}
