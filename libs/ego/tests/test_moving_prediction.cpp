// The previous frame's moving mask predicted into the next frame
// (moving_prediction.h) and the one rule that judges a mask too large.
#include <bims/ego/flags.h>
#include <bims/ego/moving_prediction.h>
#include <bims/ego/odometry.h>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "synth_scene.h"

using namespace bims::ego;
using bims::ego::test::K320;

namespace
{
constexpr int W = 320, H = 240;

/** A wall at \a z metres over the whole image. */
cv::Mat wall(float z)
{
	return cv::Mat(H, W, CV_32FC1, cv::Scalar(z));
}

double iou(const cv::Mat& a, const cv::Mat& b)
{
	cv::Mat i, u;
	cv::bitwise_and(a, b, i);
	cv::bitwise_or(a, b, u);
	return double(cv::countNonZero(i)) / std::max(1, cv::countNonZero(u));
}

/** Mask of the pixels whose point on the wall at depth z lies in the box
 * [x0, x1] x [y0, y1] of the camera at x = cam_x (metres, camera frame of
 * the first camera). */
cv::Mat boxOnWall(double z, double x0, double x1, double y0, double y1,
                  double cam_x)
{
	const Eigen::Matrix3d K = K320();
	cv::Mat m = cv::Mat::zeros(H, W, CV_8UC1);
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
		{
			const double x = z * (u - K(0, 2)) / K(0, 0) + cam_x,
			             y = z * (v - K(1, 2)) / K(1, 1);
			if (x >= x0 && x <= x1 && y >= y0 && y <= y1)
				m.at<uint8_t>(v, u) = 255;
		}
	return m;
}
}  // namespace

TEST(MovingPrediction, WithoutMotionTheMaskIsKept)
{
	cv::Mat m = cv::Mat::zeros(H, W, CV_8UC1);
	m(cv::Rect(100, 60, 40, 80)).setTo(255);
	const cv::Mat p =
	    predictMovingMask(m, wall(2), K320(), Eigen::Matrix3d::Identity(),
	                      Eigen::Vector3d::Zero(), 0);
	EXPECT_EQ(cv::countNonZero(p != m), 0);
}

TEST(MovingPrediction, TheMaskFollowsTheCameraMotion)
{
	// The camera moves 0.1 m to the right in front of a wall at 2 m: a
	// mover standing there shifts 13 px to the left in the image. The
	// prediction lands on it; the previous mask as it is does not.
	const double z = 2, dx = 0.1;
	const cv::Mat prev = boxOnWall(z, -0.3, 0.0, -0.4, 0.4, 0);
	const cv::Mat now = boxOnWall(z, -0.3, 0.0, -0.4, 0.4, dx);
	const cv::Mat p = predictMovingMask(prev, wall(float(z)), K320(),
	                                    Eigen::Matrix3d::Identity(),
	                                    Eigen::Vector3d(dx, 0, 0), 0);
	EXPECT_GT(iou(p, now), 0.93);
	EXPECT_LT(iou(prev, now), 0.7);
	// and with a rotation: 3 degrees about the optical y axis
	const Eigen::Matrix3d R =
	    Eigen::AngleAxisd(3 * M_PI / 180, Eigen::Vector3d::UnitY())
	        .toRotationMatrix();
	const cv::Mat pr = predictMovingMask(prev, wall(float(z)), K320(), R,
	                                     Eigen::Vector3d::Zero(), 0);
	cv::Mat expected = cv::Mat::zeros(H, W, CV_8UC1);
	const Eigen::Matrix3d K = K320();
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
		{
			// this pixel's ray in the previous camera hits the wall where?
			const Eigen::Vector3d r =
			    R * Eigen::Vector3d((u - K(0, 2)) / K(0, 0),
			                        (v - K(1, 2)) / K(1, 1), 1);
			const double s = z / r.z();
			const double x = s * r.x(), y = s * r.y();
			if (x >= -0.3 && x <= 0 && y >= -0.4 && y <= 0.4)
				expected.at<uint8_t>(v, u) = 255;
		}
	EXPECT_GT(iou(pr, expected), 0.9);
	EXPECT_LT(iou(prev, expected), 0.6);
}

TEST(MovingPrediction, MarginGrowsTheMaskAndPixelsWithoutDepthAreLeftOut)
{
	cv::Mat m = cv::Mat::zeros(H, W, CV_8UC1);
	m(cv::Rect(100, 60, 40, 80)).setTo(255);
	cv::Mat d = wall(2);
	d(cv::Rect(100, 60, 20, 80)).setTo(0);  // the left half has no depth
	const cv::Mat p = predictMovingMask(
	    m, d, K320(), Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 3);
	EXPECT_EQ(cv::boundingRect(p), cv::Rect(117, 57, 26, 86));
}

TEST(MovingPrediction, BadInputIsAnError)
{
	const cv::Mat m = cv::Mat::zeros(H, W, CV_8UC1);
	EXPECT_THROW(predictMovingMask(m, cv::Mat(H / 2, W / 2, CV_32FC1, 1.f),
	                               K320(), Eigen::Matrix3d::Identity(),
	                               Eigen::Vector3d::Zero(), 0),
	             std::invalid_argument);
	EXPECT_THROW(
	    predictMovingMask(m, wall(1), K320(), Eigen::Matrix3d::Identity(),
	                      Eigen::Vector3d::Zero(), -1),
	    std::invalid_argument);
	// a mover behind the camera after the motion is not drawn
	cv::Mat all(H, W, CV_8UC1, cv::Scalar(255));
	const cv::Mat p =
	    predictMovingMask(all, wall(1), K320(), Eigen::Matrix3d::Identity(),
	                      Eigen::Vector3d(0, 0, 2), 0);
	EXPECT_EQ(cv::countNonZero(p), 0);
}

TEST(MovingPrediction, AMaskOverMoreThanTheLimitIsNotUsedAndAWrongSizeIsAnError)
{
	// The previous frame's mask covers 95 % of the image: it is ignored
	// (flagged) and the frame is still measured.
	using namespace bims::ego::test;
	EgoConfig cfg;
	Odometry odo(cfg);
	const Eigen::Matrix3d R = R_WC_lookingNorth();
	const RgbdFrame f0 = render(R, Eigen::Vector3d(0, 0, 0), K320(), W, H, 0.0);
	const RgbdFrame f1 =
	    render(R, Eigen::Vector3d(0.01, 0, 0), K320(), W, H, 1 / 30.0);
	cv::Mat mask = cv::Mat::zeros(H, W, CV_8UC1);
	mask.colRange(W * 5 / 100, W).setTo(255);
	odo.processFrame(f0);
	const FrameEgomotion r = odo.processFrame(f1, &mask);
	EXPECT_TRUE(r.flags & kFlagMaskIgnored) << flagsToString(r.flags);
	EXPECT_TRUE(r.ok()) << flagsToString(r.flags);
	// a mask of the wrong size is an error, not a silent skip
	const cv::Mat small = cv::Mat::zeros(H / 2, W / 2, CV_8UC1);
	const RgbdFrame f2 =
	    render(R, Eigen::Vector3d(0.02, 0, 0), K320(), W, H, 2 / 30.0);
	EXPECT_THROW(odo.processFrame(f2, &small), std::invalid_argument);
}

TEST(MovingPrediction, TheOdometryExcludesThePredictedMaskWhenAskedTo)
{
	// The camera moves 5 cm a frame to the right; the previous mask is
	// the image's left third. Predicted into the frame with the last
	// frame's motion it moves about 9 px to the left (5 cm at 1.5 m, the
	// wall ahead), partly out of the view: the alignment then excludes
	// less than the previous mask.
	using namespace bims::ego::test;
	const Eigen::Matrix3d R = R_WC_lookingNorth();
	// {W}: the camera looks along +x; its optical x axis is world -y
	auto frame = [&](int k)
	{
		return render(R, Eigen::Vector3d(2.5, -0.05 * k, 0), K320(), W, H,
		              k / 30.0);
	};
	cv::Mat mask = cv::Mat::zeros(H, W, CV_8UC1);
	mask.colRange(0, W / 3).setTo(255);
	double share[2] = {0, 0};
	cv::Mat pred;
	for (const bool predict : {false, true})
	{
		EgoConfig cfg;
		cfg.odometry.mode = OdometryMode::Vision;
		cfg.anchor.predict_mask = predict;
		cfg.anchor.mask_margin_px = 0;
		cfg.anchor.mask_veto_consistent = 0;  // (a static region)
		Odometry odo(cfg);
		const RgbdFrame f0 = frame(0), f1 = frame(1), f2 = frame(2);
		odo.processFrame(f0);
		// (the motion the prediction takes next)
		const FrameEgomotion r1 = odo.processFrame(f1);
		const FrameEgomotion r = odo.processFrame(f2, &mask);
		EXPECT_TRUE(r.ok()) << flagsToString(r.flags);
		share[predict] = r.anchor.excluded_fraction;
		if (predict)
		{
			const auto& T = r1.T_CprevC;
			Eigen::Matrix3d Rm;
			for (int i = 0; i < 3; i++)
				for (int j = 0; j < 3; j++)
					Rm(i, j) = T.getRotationMatrix()(i, j);
			pred = predictMovingMask(mask, f1.depth, K320(), Rm,
			                         Eigen::Vector3d(T.x(), T.y(), T.z()), 0);
			// (the last motion measured: near the true 5 cm to the right)
			EXPECT_NEAR(T.x(), 0.05, 0.02);
		}
	}
	EXPECT_DOUBLE_EQ(share[0], (W / 3) / double(W));
	// the exclusion is the prediction with the last motion measured
	EXPECT_NEAR(share[1], cv::countNonZero(pred) / double(W * H),
	            1.0 / (W * H));
	EXPECT_LT(share[1], share[0] - 0.01);
}
