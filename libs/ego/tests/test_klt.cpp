// GyroAidedKLT: the infinite homography, tracking through fast rotations
// with and without the gyro aid, forward-backward check and the moving mask.
#include <bims/common/so3.h>
#include <bims/ego/gyro_klt.h>
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "synth_scene.h"

using namespace bims;  // so3.h
using namespace bims::ego;

namespace
{
using test::K320;
Eigen::Vector2d project(const Eigen::Matrix3d& K, const Eigen::Vector3d& p)
{
	const Eigen::Vector3d x = K * p;
	return x.head<2>() / x.z();
}

// Fraction of tracks within 2 px of the position the true motion predicts
// (rendered scene: true position = projection of the back-projected point).
struct Score
{
	int good = 0, total = 0;
	double frac() const { return total ? double(good) / total : 0; }
};
Score scoreTracks(const std::vector<Track>& tracks, const RgbdFrame& f0,
                  const Eigen::Matrix3d& R_C0C1, const Eigen::Vector3d& t_C0C1)
{
	Score s;
	for (const auto& tr : tracks)
	{
		const float z = depthAt(f0.depth, tr.prev);
		if (z <= 0) continue;
		const Eigen::Vector3d p0 = backProject(f0.K, tr.prev, z);
		const Eigen::Vector3d p1 = R_C0C1.transpose() * (p0 - t_C0C1);
		const Eigen::Vector2d x = project(f0.K, p1);
		++s.total;
		if (std::hypot(x.x() - tr.cur.x, x.y() - tr.cur.y) < 2.0) ++s.good;
	}
	return s;
}
}  // namespace

TEST(GyroAidedKLT, InfiniteHomographyMatchesProjectedPoints)
{
	const Eigen::Matrix3d K = K320();
	const Eigen::Matrix3d R_C0C1 = expSO3(Eigen::Vector3d(0.05, -0.12, 0.3));
	std::mt19937 rng(7);
	std::uniform_real_distribution<double> U(-1, 1), Z(0.5, 20);
	for (int i = 0; i < 100; i++)
	{
		const double z = Z(rng);
		const Eigen::Vector3d p0(U(rng) * z * 0.6, U(rng) * z * 0.45, z);
		const Eigen::Vector3d p1 = R_C0C1.transpose() * p0;  // pure rotation
		if (p1.z() <= 0.1) continue;
		const Eigen::Vector2d x0 = project(K, p0), x1 = project(K, p1);
		const cv::Point2f y =
		    GyroAidedKLT::warp(GyroAidedKLT::infiniteHomography(K, R_C0C1),
		                       cv::Point2f(float(x0.x()), float(x0.y())));
		EXPECT_NEAR(y.x, x1.x(), 2e-3);
		EXPECT_NEAR(y.y, x1.y(), 2e-3);
	}
}

TEST(GyroAidedKLT, GyroAidTracksFastRotation)
{
	// 8 deg of pan + 3 deg roll between frames (240 deg/s at 30 Hz): a
	// ~37 px image motion plus rotation, beyond a 2-level pyramid with a
	// 15 px window; the gyro prediction puts LK back in its basin.
	const Eigen::Matrix3d K = K320();
	const Eigen::Matrix3d R0 = test::R_WC_lookingNorth();
	const Eigen::Matrix3d R_C0C1 =
	    expSO3(Eigen::Vector3d(0.0, 8 * M_PI / 180, 3 * M_PI / 180));
	const Eigen::Vector3d t_C0C1(0.02, 0, 0.01);
	const RgbdFrame f0 = test::render(R0, {0, 0, 0}, K, 320, 240, 0);
	const RgbdFrame f1 =
	    test::render(R0 * R_C0C1, R0 * t_C0C1, K, 320, 240, 1 / 30.);
	TrackerParams p;
	p.window = 15;
	p.pyramid_levels = 1;
	p.max_features = 200;
	Score aided, plain;
	{
		GyroAidedKLT klt(p);
		klt.track(f0.grey, K, nullptr, nullptr);
		aided = scoreTracks(klt.track(f1.grey, K, &R_C0C1, nullptr), f0, R_C0C1,
		                    t_C0C1);
		EXPECT_EQ(klt.stats().attempted, 200);
	}
	{
		GyroAidedKLT klt(p);
		klt.track(f0.grey, K, nullptr, nullptr);
		plain = scoreTracks(klt.track(f1.grey, K, nullptr, nullptr), f0, R_C0C1,
		                    t_C0C1);
	}
	EXPECT_GT(aided.good, 120);  // most visible features survive, correct
	EXPECT_GT(aided.frac(), 0.95);
	EXPECT_LT(plain.good, aided.good / 2);
}

TEST(GyroAidedKLT, TracksSlowMotionAccurately)
{
	const Eigen::Matrix3d K = K320();
	const Eigen::Matrix3d R0 = test::R_WC_lookingNorth();
	const Eigen::Matrix3d R_C0C1 = expSO3(Eigen::Vector3d(0.01, 0.02, 0.0));
	const Eigen::Vector3d t_C0C1(0.01, 0.0, 0.02);
	const RgbdFrame f0 = test::render(R0, {0, 0, 0}, K, 320, 240, 0);
	const RgbdFrame f1 = test::render(R0 * R_C0C1, R0 * t_C0C1, K, 320, 240, 1);
	TrackerParams p;
	p.max_features = 300;
	GyroAidedKLT klt(p);
	klt.track(f0.grey, K, nullptr, nullptr);
	EXPECT_GT(klt.numFeatures(), 250u);
	const Score s = scoreTracks(klt.track(f1.grey, K, &R_C0C1, nullptr), f0,
	                            R_C0C1, t_C0C1);
	EXPECT_GT(s.total, 200);
	EXPECT_GT(s.frac(), 0.97);
}

TEST(GyroAidedKLT, ReplenishesOnAGrid)
{
	const Eigen::Matrix3d K = K320();
	const RgbdFrame f0 =
	    test::render(test::R_WC_lookingNorth(), {0, 0, 0}, K, 320, 240, 0);
	TrackerParams p;
	p.grid_cols = 4;
	p.grid_rows = 3;
	p.max_features = 120;
	GyroAidedKLT klt(p);
	klt.track(f0.grey, K, nullptr, nullptr);
	const auto& tr = klt.track(f0.grey, K, nullptr, nullptr);  // same image
	ASSERT_EQ(tr.size(), 120u);
	std::vector<int> cells(12, 0);
	for (const auto& t : tr)
	{
		EXPECT_NEAR(t.cur.x, t.prev.x, 0.05);
		EXPECT_NEAR(t.cur.y, t.prev.y, 0.05);
		++cells[int(t.prev.y * 3 / 240) * 4 + int(t.prev.x * 4 / 320)];
	}
	for (int c : cells) EXPECT_EQ(c, 10);
}

TEST(GyroAidedKLT, MovingMaskExcludesFeatures)
{
	const Eigen::Matrix3d K = K320();
	const RgbdFrame f0 =
	    test::render(test::R_WC_lookingNorth(), {0, 0, 0}, K, 320, 240, 0);
	cv::Mat mask(240, 320, CV_8UC1, cv::Scalar(0));
	mask(cv::Rect(0, 0, 160, 240)).setTo(255);  // left half "moving"
	GyroAidedKLT klt;
	klt.track(f0.grey, K, nullptr, nullptr);
	const size_t before = klt.numFeatures();
	const auto& tr = klt.track(f0.grey, K, nullptr, &mask);
	EXPECT_GT(klt.stats().droppedMask, int(before / 3));
	for (const auto& t : tr) EXPECT_GE(t.prev.x, 160.f);
	// New features are not detected in the (dilated) masked region either.
	const auto& tr2 = klt.track(f0.grey, K, nullptr, nullptr);
	for (const auto& t : tr2) EXPECT_GE(t.prev.x, 160.f);
}

TEST(GyroAidedKLT, MaskDilationAroundTheMoversEqualsTheWholeImages)
{
	const cv::Mat kernel =
	    cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(17, 17));
	std::mt19937 rng(3);
	std::uniform_int_distribution<int> x(0, 319), y(0, 239), r(1, 30);
	for (int k = 0; k < 12; k++)
	{
		cv::Mat mask(240, 320, CV_8UC1, cv::Scalar(0));
		// blobs anywhere, at the borders and corners too; k = 0: empty
		for (int b = 0; b < k % 4; b++)
			cv::circle(mask, {x(rng), y(rng)}, r(rng), 255, cv::FILLED);
		if (k == 5) mask.at<uint8_t>(0, 319) = 255;
		if (k == 6) mask.at<uint8_t>(239, 0) = 7;
		cv::Mat whole;
		cv::dilate(mask, whole, kernel);
		const cv::Mat ours = dilateMask(mask, 8);
		ASSERT_EQ(ours.size(), mask.size());
		ASSERT_EQ(ours.type(), CV_8UC1);
		EXPECT_EQ(cv::countNonZero(ours != whole), 0) << "mask " << k;
		if (k == 0)
		{
			EXPECT_EQ(cv::countNonZero(ours), 0);
		}
	}
}

TEST(GyroAidedKLT, RejectsBadImages)
{
	GyroAidedKLT klt;
	const Eigen::Matrix3d K = K320();
	EXPECT_THROW(klt.track(cv::Mat(), K, nullptr, nullptr),
	             std::invalid_argument);
	EXPECT_THROW(klt.track(cv::Mat(10, 10, CV_32FC1), K, nullptr, nullptr),
	             std::invalid_argument);
	klt.track(cv::Mat(240, 320, CV_8UC1, cv::Scalar(0)), K, nullptr, nullptr);
	EXPECT_EQ(klt.numFeatures(), 0u);  // flat image: nothing to track
	EXPECT_THROW(klt.track(cv::Mat(120, 160, CV_8UC1), K, nullptr, nullptr),
	             std::invalid_argument);
}
