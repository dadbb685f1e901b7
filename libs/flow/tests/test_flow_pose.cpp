// Dense-flow pose refinement (and its Jacobian against central differences),
// structure tensor, visibility gate, depth edges.
#include <bims/flow/consistency.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/flow_pose.h>
#include <bims/flow/observed_flow.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "test_util.h"

using namespace bims::flow;
using mrpt::poses::CPose3D;

namespace
{
/** A room-like depth: a slanted wall with a box in front (CV_32FC1). */
cv::Mat roomDepth(int W, int H)
{
	cv::Mat d(H, W, CV_32FC1);
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
			d.at<float>(v, u) =
			    static_cast<float>(2.5 + 1.5 * u / W + 0.5 * v / H);
	d(cv::Rect(W / 3, H / 3, W / 4, H / 4)).setTo(1.2f);
	return d;
}

double rotDeg(const CPose3D& a, const CPose3D& b)
{
	const auto R = (b - a).getRotationMatrix();
	const double c =
	    std::clamp((R(0, 0) + R(1, 1) + R(2, 2) - 1) / 2, -1.0, 1.0);
	return std::acos(c) * 180 / M_PI;
}

double transDist(const CPose3D& a, const CPose3D& b)
{
	return std::sqrt((a.x() - b.x()) * (a.x() - b.x()) +
	                 (a.y() - b.y()) * (a.y() - b.y()) +
	                 (a.z() - b.z()) * (a.z() - b.z()));
}

const CPose3D kTrue(0.012, -0.004, 0.010, 0.006, -0.004, 0.003);  // ~0.45 deg
const CPose3D kInit(0.020, 0.002, 0.000, 0.0, 0.0, 0.0);
}  // namespace

TEST(FlowPose, Se3RecoversTheTruePoseFromExactFlow)
{
	const int W = 320, H = 240;
	const auto cam = test::vgaCamera(W, H);
	const cv::Mat depth = roomDepth(W, H);
	const cv::Mat obs = expectedFlowExact(depth, cam, kTrue);
	FlowPoseParams p;
	const auto r = refinePoseWithFlow(obs, depth, cam, kInit, p);
	ASSERT_TRUE(r.ok);
	EXPECT_GT(r.samples, 1000);
	EXPECT_LT(rotDeg(r.T_CprevC, kTrue), 1e-3);
	EXPECT_LT(transDist(r.T_CprevC, kTrue), 1e-4);
	EXPECT_GT(r.median_px_before, 1.0);
	EXPECT_LT(r.median_px_after, 1e-3);
}

TEST(FlowPose, TranslationModeKeepsTheRotation)
{
	const int W = 320, H = 240;
	const auto cam = test::vgaCamera(W, H);
	const cv::Mat depth = roomDepth(W, H);
	const cv::Mat obs = expectedFlowExact(depth, cam, kTrue);
	FlowPoseParams p;
	p.mode = FlowPoseMode::Translation;
	// init with the true rotation and a wrong translation
	CPose3D init = kTrue;
	init.x(0.03);
	init.z(-0.01);
	const auto r = refinePoseWithFlow(obs, depth, cam, init, p);
	ASSERT_TRUE(r.ok);
	EXPECT_LT(rotDeg(r.T_CprevC, init), 1e-9);
	EXPECT_LT(transDist(r.T_CprevC, kTrue), 1e-4);
}

TEST(FlowPose, IgnoresAMovingMinority)
{
	const int W = 320, H = 240;
	const auto cam = test::vgaCamera(W, H);
	const cv::Mat depth = roomDepth(W, H);
	cv::Mat obs = expectedFlowExact(depth, cam, kTrue);
	// 30 % of the image moves on its own by (6, -3) px
	const cv::Rect mover(0, 0, W * 3 / 10, H);
	obs(mover) += cv::Scalar(6.0f, -3.0f);
	const auto r = refinePoseWithFlow(obs, depth, cam, kInit, FlowPoseParams{});
	ASSERT_TRUE(r.ok);
	EXPECT_LT(rotDeg(r.T_CprevC, kTrue), 0.01);
	EXPECT_LT(transDist(r.T_CprevC, kTrue), 1e-3);
	EXPECT_NEAR(r.inlier_fraction, 0.7, 0.05);
}

TEST(FlowPose, TexturelessSamplesAreNotUsed)
{
	const int W = 320, H = 240;
	const auto cam = test::vgaCamera(W, H);
	const cv::Mat depth = roomDepth(W, H);
	cv::Mat obs = expectedFlowExact(depth, cam, kTrue);
	// the right half is a blank wall whose (wrong) flow is zero
	cv::Mat grey = test::texture(W, H, 3);
	grey(cv::Rect(W / 2, 0, W / 2, H)).setTo(128);
	obs(cv::Rect(W / 2, 0, W / 2, H)).setTo(cv::Scalar(0.0f, 0.0f));
	const cv::Mat S = structureTensor(grey, 9);
	const auto r = refinePoseWithFlow(obs, depth, cam, kInit, FlowPoseParams{},
	                                  nullptr, &S);
	ASSERT_TRUE(r.ok);
	// (pixels within half a window of the blank half still pass the texture
	// test; Tukey drops most of them)
	EXPECT_LT(rotDeg(r.T_CprevC, kTrue), 0.01);
	EXPECT_LT(transDist(r.T_CprevC, kTrue), 5e-4);
	// without the tensor the blank half's zero flow drags the fit away
	const auto r0 =
	    refinePoseWithFlow(obs, depth, cam, kInit, FlowPoseParams{});
	EXPECT_GT(rotDeg(r0.T_CprevC, kTrue), 10 * rotDeg(r.T_CprevC, kTrue));
}

TEST(FlowPose, TooFewSamplesKeepTheInitialPose)
{
	const auto cam = test::vgaCamera(320, 240);
	const cv::Mat depth(240, 320, CV_32FC1, cv::Scalar(0.0f));
	const cv::Mat obs(240, 320, CV_32FC2, cv::Scalar(1.0f, 0.0f));
	const auto r = refinePoseWithFlow(obs, depth, cam, kInit, FlowPoseParams{});
	EXPECT_FALSE(r.ok);
	EXPECT_EQ(r.samples, 0);
	EXPECT_LT(transDist(r.T_CprevC, kInit), 1e-12);
}

TEST(FlowPose, BadInputThrows)
{
	const auto cam = test::vgaCamera(320, 240);
	const cv::Mat depth(240, 320, CV_32FC1, cv::Scalar(2.0f));
	const cv::Mat obs(240, 320, CV_32FC2, cv::Scalar(0.0f, 0.0f));
	const cv::Mat small(100, 100, CV_32FC2, cv::Scalar(0.0f, 0.0f));
	const cv::Mat badMask(240, 320, CV_32FC1, cv::Scalar(0.0f));
	FlowPoseParams p;
	EXPECT_THROW(refinePoseWithFlow(small, depth, cam, kInit, p),
	             std::invalid_argument);
	EXPECT_THROW(refinePoseWithFlow(obs, depth, cam, kInit, p, &badMask),
	             std::invalid_argument);
	EXPECT_THROW(refinePoseWithFlow(obs, depth, cam, kInit, p, nullptr, &obs),
	             std::invalid_argument);
	p.step_px = 0;
	EXPECT_THROW(refinePoseWithFlow(obs, depth, cam, kInit, p),
	             std::invalid_argument);
	FlowParams none;
	none.refine_pose = RefinePose::None;  // nothing to refine
	EXPECT_THROW(flowPoseParamsFrom(none), std::invalid_argument);
	EXPECT_THROW(structureTensor(cv::Mat(), 9), std::invalid_argument);
	EXPECT_THROW(depthEdgeMask(obs, 0.05, 2), std::invalid_argument);
}

TEST(StructureTensor, MeasuresTheRmsIntensityChangeOfAShift)
{
	// intensity ramp along x, 2 grey levels per pixel: a shift d changes the
	// image by 2 d_x, nothing along y (aperture).
	cv::Mat grey(60, 80, CV_8UC1);
	for (int v = 0; v < grey.rows; v++)
		for (int u = 0; u < grey.cols; u++)
			grey.at<uint8_t>(v, u) = static_cast<uint8_t>(40 + 2 * u);
	const cv::Mat S = structureTensor(grey, 9);
	const cv::Vec3f s = S.at<cv::Vec3f>(30, 40);
	EXPECT_NEAR(s[0], 4.0, 1e-3);
	EXPECT_NEAR(s[1], 0.0, 1e-3);
	EXPECT_NEAR(s[2], 0.0, 1e-3);
	EXPECT_NEAR(minEigen(s), 0.0, 1e-3);
}

TEST(Consistency, VisibilityGateIgnoresFlowDifferencesOnBlankSurfaces)
{
	const int W = 160, H = 120;
	const auto cam = test::vgaCamera(W, H);
	const cv::Mat depth(H, W, CV_32FC1, cv::Scalar(2.0f));
	const CPose3D T;
	const cv::Mat exp = expectedFlowExact(depth, cam, T);
	const cv::Mat obs(H, W, CV_32FC2, cv::Scalar(3.0f, 0.0f));  // 3 px off
	cv::Mat grey = test::texture(W, H, 5);
	grey(cv::Rect(0, 0, W / 2, H)).setTo(100);  // left half blank
	const cv::Mat S = structureTensor(grey, 9);
	FlowParams p;
	p.visible_change_grey = 8;
	const cv::Mat lab =
	    labelConsistency(obs, exp, depth, cam, T, p, nullptr, &S);
	EXPECT_EQ(lab.at<int8_t>(H / 2, W / 4), kNotDiff);
	EXPECT_EQ(lab.at<int8_t>(H / 2, 3 * W / 4), kDiff);
	// without the gate both are Diff; the gate needs the tensor
	p.visible_change_grey = 0;
	const cv::Mat lab0 = labelConsistency(obs, exp, depth, cam, T, p);
	EXPECT_EQ(lab0.at<int8_t>(H / 2, W / 4), kDiff);
	p.visible_change_grey = 8;
	EXPECT_THROW(labelConsistency(obs, exp, depth, cam, T, p),
	             std::invalid_argument);
}

TEST(Consistency, DepthEdgesGetNoLabel)
{
	const int W = 160, H = 120;
	const auto cam = test::vgaCamera(W, H);
	cv::Mat depth(H, W, CV_32FC1, cv::Scalar(3.0f));
	depth(cv::Rect(0, 0, W / 2, H)).setTo(1.0f);  // step at u = W/2
	const cv::Mat edges = depthEdgeMask(depth, 0.05, 2);
	EXPECT_EQ(edges.at<uint8_t>(H / 2, W / 2 - 1), 255);
	EXPECT_EQ(edges.at<uint8_t>(H / 2, W / 2 + 1), 255);
	EXPECT_EQ(edges.at<uint8_t>(H / 2, W / 4), 0);
	const CPose3D T;
	const cv::Mat exp = expectedFlowExact(depth, cam, T);
	const cv::Mat obs(H, W, CV_32FC2, cv::Scalar(0.0f, 0.0f));
	FlowParams p;
	p.visible_change_grey = 0;  // no tensor: the gate off
	p.depth_edge_rel = 0.05;
	const cv::Mat lab = labelConsistency(obs, exp, depth, cam, T, p);
	EXPECT_EQ(lab.at<int8_t>(H / 2, W / 2), kNoLabel);
	EXPECT_EQ(lab.at<int8_t>(H / 2, W / 4), kNotDiff);
}

// The Jacobian of refinePoseWithFlow()'s flow residual (observed position -
// projection) against central differences under the fit's increment
// (w, v): R <- Exp(w) R, t <- Exp(w) t + v; random poses and points.
TEST(FlowPose, JacobianMatchesCentralDifferences)
{
	const auto cam = test::vgaCamera();
	const double fx = cam.fx(), fy = cam.fy(), cx = cam.cx(), cy = cam.cy();
	std::mt19937 rng(20240611);
	std::uniform_real_distribution<double> U(-1, 1), Zd(0.5, 5);
	const auto Exp = [](const Eigen::Vector3d& w)
	{
		const double th = w.norm();
		return th > 0 ? Eigen::AngleAxisd(th, w / th).toRotationMatrix()
		              : Eigen::Matrix3d(Eigen::Matrix3d::Identity());
	};
	const double h = 1e-6, tol = 1e-5;
	double maxAbs = 0, maxRel = 0;
	int n = 0;
	while (n < 40)
	{
		const Eigen::Matrix3d R =
		    Exp(0.4 * Eigen::Vector3d(U(rng), U(rng), U(rng)));
		const Eigen::Vector3d t = 0.3 * Eigen::Vector3d(U(rng), U(rng), U(rng));
		const double z = Zd(rng);
		const Eigen::Vector3d p(0.6 * z * U(rng), 0.45 * z * U(rng), z);
		const Eigen::Vector3d q = R * p + t;
		if (q.z() < 0.3) continue;
		++n;
		// an observed position a few pixels off the projection
		const Eigen::Vector2d x(fx * q.x() / q.z() + cx + 5 * U(rng),
		                        fy * q.y() / q.z() + cy + 5 * U(rng));
		const auto residual = [&](const Eigen::Matrix<double, 6, 1>& xi)
		{
			const Eigen::Matrix3d dR = Exp(xi.head<3>());
			const Eigen::Vector3d qq = dR * R * p + (dR * t + xi.tail<3>());
			return Eigen::Vector2d(x.x() - (fx * qq.x() / qq.z() + cx),
			                       x.y() - (fy * qq.y() / qq.z() + cy));
		};
		// the residual's Jacobian is minus the projection's
		const Eigen::Matrix<double, 2, 6> J = -flowPoseJacobian(q, fx, fy);
		Eigen::Matrix<double, 2, 6> num;
		for (int k = 0; k < 6; k++)
		{
			Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
			d(k) = h;
			num.col(k) = (residual(d) - residual(-d)) / (2 * h);
		}
		for (int row = 0; row < 2; row++)
		{
			// relative to the row's largest entry
			const double scale = num.row(row).cwiseAbs().maxCoeff();
			const double e = (J.row(row) - num.row(row)).cwiseAbs().maxCoeff();
			maxAbs = std::max(maxAbs, e);
			maxRel = std::max(maxRel, e / scale);
			EXPECT_LT(e / scale, tol) << "sample " << n << ", row " << row;
		}
	}
	std::printf("flow residual: max abs %.2e, rel %.2e\n", maxAbs, maxRel);
}
