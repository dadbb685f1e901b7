// pose_check.h (bims-flow-check's scores): a wall with a box in front, the
// camera's true motion known; the observed flow is the truth's expected
// flow, so the true pose explains every pixel and a wrong one does not.
#include <bims/flow/expected_flow.h>
#include <bims/flow/pose_check.h>
#include <gtest/gtest.h>

#include <cmath>

#include "test_util.h"

using namespace bims::flow;
using mrpt::poses::CPose3D;

namespace
{
struct Scene
{
	mrpt::img::TCamera cam = test::vgaCamera(160, 120);
	cv::Mat depth, grey;
	FlowParams p;
	// 2 cm to the right, 0.5 degrees of yaw
	CPose3D truth{0.02, 0, 0, 0.5 * M_PI / 180, 0, 0};
	cv::Mat observed;
	Scene()
	{
		depth = cv::Mat(120, 160, CV_32FC1, cv::Scalar(2.0f));
		depth(cv::Rect(60, 40, 40, 40)).setTo(1.2f);  // a box: depth edges
		grey = test::texture(160, 120, 3);
		observed = expectedFlow(p.expected, depth, cam, truth);
	}
};
}  // namespace

TEST(PoseCheck, RotationAndTranslationBetweenPoses)
{
	const CPose3D a(1, 2, 3, 0.3, 0.2, 0.1);
	const CPose3D b = a + CPose3D(0, 0, 0, 30 * M_PI / 180, 0, 0);
	EXPECT_NEAR(rotationDeg(a, b), 30, 1e-9);
	EXPECT_NEAR(rotationDeg(a, a), 0, 1e-6);
	EXPECT_NEAR(translationMm(CPose3D(0.3, 0.4, 0, 0, 0, 0), CPose3D()), 500,
	            1e-9);
}

TEST(PoseCheck, TheTruePoseExplainsTheFlowAndAWrongOneDoesNot)
{
	const Scene s;
	const double validPx = 160 * 120;
	const cv::Mat S = cv::Mat();  // no texture test: tensor unused
	FlowParams p = s.p;
	p.visible_change_grey = 0;
	cv::Mat lab;
	const auto good =
	    scorePose(s.observed, s.depth, s.cam, s.truth, p, validPx, S, &lab);
	EXPECT_EQ(good.diffFraction, 0);
	EXPECT_LT(good.medianPx, 1e-3);
	EXPECT_GT(cv::countNonZero(lab == 0), 0.9 * validPx);  // notDiff
	// 10 cm more to the right: 6.5 px more on the wall, 11 px on the box
	const auto bad =
	    scorePose(s.observed, s.depth, s.cam,
	              s.truth + CPose3D(0.1, 0, 0, 0, 0, 0), p, validPx, S);
	EXPECT_GT(bad.diffFraction, 0.9);
	EXPECT_GT(bad.medianPx, 5);
	EXPECT_LT(bad.medianPx, 12);
}

TEST(PoseCheck, FourSourcesOneFrame)
{
	const Scene s;
	const CPose3D wrong = s.truth + CPose3D(0.1, 0, 0, 0, 0, 0);
	const auto c = checkPoseSources(s.observed, s.depth, s.grey, s.cam, s.truth,
	                                wrong, s.truth, s.p);
	const auto& v = c.values;
	EXPECT_EQ(c.validPx, 160 * 120);
	EXPECT_EQ(PoseSourceCheck::names().size(), v.size());
	EXPECT_STREQ(PoseSourceCheck::names()[1], "diff_%_used");
	EXPECT_LT(v[0], 1);             // ego = truth: Diff % ~ 0
	EXPECT_GT(v[1], 90);            // used: wrong
	EXPECT_LT(v[2], 1);             // gt
	EXPECT_LT(v[3], 1);             // fitted from ego = truth: stays there
	EXPECT_NEAR(v[8], 0, 1e-6);     // rot ego-gt
	EXPECT_LT(v[9], 0.05);          // rot ego-flow
	EXPECT_NEAR(v[12], 0, 1e-6);    // t ego-gt [mm]
	EXPECT_LT(v[13], 2.0);          // t ego-flow [mm]
	EXPECT_NEAR(v[15], 100, 2.0);   // t used-flow [mm]
	EXPECT_NEAR(v[16], 0.5, 1e-6);  // gt rotation [deg]
	EXPECT_NEAR(v[17], 20, 1e-6);   // gt translation [mm]
	// the used pose's Diff pixels: in the labels, some on the box's edges
	EXPECT_EQ(cv::countNonZero(c.labelsUsed == 1),
	          std::lround(v[1] / 100 * c.validPx));
	EXPECT_GT(v[18], 0);
	EXPECT_LT(v[18], 0.5);
}
