#include <bims/common/config.h>
#include <bims/flow/consistency.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/observed_flow.h>
#include <bims_test/presets.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include "test_util.h"

using namespace bims::flow;

// A fronto-parallel textured wall at 2 m, the camera translating sideways, and
// a flat object in front of the wall moving on its own: the object's pixels
// must be Diff, the wall's notDiff.
TEST(Consistency, MovingPatchIsDiffAndStaticBackgroundIsNot)
{
	const int W = 320, H = 240;
	const auto cam = test::vgaCamera(W, H);
	const double z = 2.0, tx = 0.02;  // camera moves +x by 2 cm
	// Camera {C(t)} at +tx in {C(t-1)}: T_CprevC translation (tx, 0, 0).
	const mrpt::poses::CPose3D T_CprevC(tx, 0, 0, 0, 0, 0);
	const double s =
	    cam.fx() * tx / z;  // wall content moves by -s in the image
	const cv::Mat wall = test::texture(W, H, 11), obj = test::texture(W, H, 12);
	const cv::Rect r0(140, 90, 60, 60);
	const cv::Point m(7, 3);  // extra image motion of the object
	cv::Mat prev = wall.clone(), cur = test::shifted(wall, -s, 0);
	obj(r0).copyTo(prev(r0));
	const cv::Rect r1(r0.x + m.x, r0.y + m.y, r0.width, r0.height);
	test::shifted(obj, -s, 0)(r0).copyTo(cur(r1));

	cv::Mat depth(H, W, CV_32FC1, cv::Scalar(static_cast<float>(z)));
	depth(cv::Rect(0, 0, W, 4)).setTo(0.0f);  // a strip without depth
	// the paper's labels: no visibility gate, a 1.5 px threshold
	auto p = bims::test::paperPreset<FlowParams>("flow");
	ObservedFlow of(p);
	const cv::Mat obs = of.compute(prev, cur);
	const cv::Mat exp = expectedFlowExact(depth, cam, T_CprevC);
	LabelStats st;
	const cv::Mat lab =
	    labelConsistency(obs, exp, depth, cam, T_CprevC, p, &st);

	size_t objDiff = 0, objN = 0, bgDiff = 0, bgN = 0;
	const cv::Rect inner(r1.x + 8, r1.y + 8, r1.width - 16, r1.height - 16);
	const cv::Rect outer(r1.x - 20, r1.y - 20, r1.width + 40, r1.height + 40);
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
		{
			const int8_t l = lab.at<int8_t>(v, u);
			if (v < 4)
			{
				EXPECT_EQ(l, kNoLabel);
				continue;
			}
			if (inner.contains({u, v}))
			{
				objN++;
				objDiff += (l == kDiff);
			}
			else if (!outer.contains({u, v}) && l != kNoLabel)
			{
				bgN++;
				bgDiff += (l == kDiff);
			}
		}
	EXPECT_GT(double(objDiff) / objN, 0.9);
	EXPECT_LT(double(bgDiff) / bgN, 0.02);
	EXPECT_EQ(st.diff + st.notDiff + st.none, size_t(W * H));
	EXPECT_GE(st.none, size_t(4 * W));
}

TEST(Consistency, ParamsRejectUnknownKeysAndBadValues)
{
	FlowParams p;
	mrpt::config::CConfigFileMemory ok(
	    "[flow]\nmethod = farneback\ndiff_threshold_px = 2.5\n");
	p.loadFromConfigFile(ok);
	EXPECT_EQ(p.method, FlowMethod::Farneback);
	EXPECT_DOUBLE_EQ(p.diff_threshold_px, 2.5);
	mrpt::config::CConfigFileMemory typo("[flow]\ndiff_treshold_px = 2.5\n");
	EXPECT_THROW(p.loadFromConfigFile(typo), bims::ConfigError);
	mrpt::config::CConfigFileMemory bad("[flow]\nmethod = lucas\n");
	EXPECT_THROW(p.loadFromConfigFile(bad), bims::ConfigError);
	mrpt::config::CConfigFileMemory neg("[flow]\ndiff_threshold_px = -1\n");
	EXPECT_THROW(p.loadFromConfigFile(neg), bims::ConfigError);
}
