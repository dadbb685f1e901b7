// R_IC estimation from gyro vs visual relative rotations.
#include <bims/common/so3.h>
#include <bims/ego/rotation_calibration.h>
#include <gtest/gtest.h>

#include <random>

using namespace bims;  // so3.h
using namespace bims::ego;

TEST(RotationCalibration, RecoversR_ICWithNoiseAndOutliers)
{
	const Eigen::Matrix3d R_IC = expSO3(Eigen::Vector3d(0.4, -2.0, 0.7));
	std::mt19937 rng(11);
	std::normal_distribution<double> N(0, 1);
	std::vector<RotationPair> pairs;
	for (int i = 0; i < 200; i++)
	{
		const Eigen::Vector3d w(0.05 * N(rng), 0.05 * N(rng), 0.05 * N(rng));
		const Eigen::Matrix3d Rc = expSO3(w);
		Eigen::Matrix3d Ri = R_IC * Rc * R_IC.transpose();
		Ri = Ri * expSO3(0.001 * Eigen::Vector3d(N(rng), N(rng), N(rng)));
		pairs.push_back(
		    {Ri, i % 5 == 0 ? Eigen::Matrix3d(expSO3(-3 * w)) : Rc});
	}
	const RotationCalibResult r = estimateRotationIC(pairs);
	ASSERT_TRUE(r.ok);
	EXPECT_LT(angleSO3(r.R_IC.transpose() * R_IC) * 180 / M_PI, 0.2);
	EXPECT_LE(r.inliers, 160);
	EXPECT_GT(r.inliers, 120);
}

TEST(RotationCalibration, ReportsUnobservableSingleAxisMotion)
{
	std::vector<RotationPair> pairs;
	for (int i = 0; i < 50; i++)
	{
		const Eigen::Matrix3d R =
		    expSO3(Eigen::Vector3d(0, 0.05 * (i % 7 - 3), 0));
		pairs.push_back({R, R});
	}
	EXPECT_FALSE(estimateRotationIC(pairs).ok);
	EXPECT_FALSE(estimateRotationIC({}).ok);
}

// The uncertainty it reports is the spread of the estimate: over many
// noisy sequences the estimate's error about the reported worst axis has
// about that standard deviation, and mostly one-axis motion makes it large.
TEST(RotationCalibration, ReportedUncertaintyIsTheEstimatesSpread)
{
	const Eigen::Matrix3d R_IC = expSO3(Eigen::Vector3d(0.4, -2.0, 0.7));
	for (const double minor : {1.0, 0.1})
	{
		std::mt19937 rng(5);
		std::normal_distribution<double> N(0, 1);
		double sumSq = 0, reported = 0;
		const int runs = 60;
		Eigen::Vector3d axis = Eigen::Vector3d::Zero();
		for (int run = 0; run < runs; run++)
		{
			std::vector<RotationPair> pairs;
			for (int i = 0; i < 150; i++)
			{
				// mostly about the camera's y axis when minor is small
				const Eigen::Vector3d w(minor * 0.01 * N(rng), 0.01 * N(rng),
				                        minor * 0.01 * N(rng));
				const Eigen::Matrix3d Rc = expSO3(w);
				Eigen::Matrix3d Ri = R_IC * Rc * R_IC.transpose();
				Ri = Ri *
				     expSO3(0.0005 * Eigen::Vector3d(N(rng), N(rng), N(rng)));
				pairs.push_back({Ri, Rc});
			}
			const RotationCalibResult r =
			    estimateRotationIC(pairs, 0.0, 5.0, run + 1);
			ASSERT_EQ(r.inliers, 150);
			if (run == 0) axis = r.weakAxis_I;
			// the error about the first run's worst axis (in {I})
			const double e =
			    logSO3(r.R_IC * R_IC.transpose()).dot(axis) * 180 / M_PI;
			sumSq += e * e;
			reported += r.uncertainty_deg / runs;
		}
		const double spread = std::sqrt(sumSq / runs);
		EXPECT_NEAR(spread, reported, 0.35 * reported) << minor;
		if (minor < 1)
			EXPECT_GT(reported, 1.0);
		else
			EXPECT_LT(reported, 0.3);
	}
}

TEST(RotationCalibration, IntegratesGyroExactlyForConstantRate)
{
	std::deque<ImuSample> s;
	const Eigen::Vector3d w(0.3, -0.2, 0.5);
	for (int i = 0; i <= 100; i++)
	{
		ImuSample x;
		x.t = i * 0.01;
		x.hasGyro = true;
		x.gyro = w;
		s.push_back(x);
	}
	const auto R = integrateGyro(s, 0.123, 0.456);
	ASSERT_TRUE(R.has_value());
	EXPECT_LT(angleSO3(R->transpose() * expSO3(w * (0.456 - 0.123))), 1e-9);
	EXPECT_FALSE(integrateGyro(s, -0.1, 0.5).has_value());  // not covered
	s.erase(s.begin() + 40, s.begin() + 60);                // 0.2 s gap
	EXPECT_FALSE(integrateGyro(s, 0.3, 0.7).has_value());
}
