// Behaviour on rendered scenes (own box ray caster, see scene_raycaster.h):
// static scene -> almost nothing flagged; a box moving into free space is
// flagged; with decay = raycast a static object that leaves the field of
// view is not forgotten (with decay = all it is).
#include <bims/maps/motion_grids.h>

#include <gtest/gtest.h>

#include "scene_raycaster.h"
#include "test_util.h"

using namespace bims::maps;
using namespace bims::maps::test;

namespace
{
constexpr int W = 96, H = 72;
}

TEST(Scenes, StaticSceneTier1FlagsUnderOnePercentAfterNFrames)
{
	for (auto mode : {DecayMode::All, DecayMode::Frustum, DecayMode::Raycast})
	{
		GridParams p = test::paperGrids();
		p.decay = mode;
		MotionGrids mg(p);
		auto scene = room();
		scene.push_back({{1.5, -0.5, 0}, {2.0, 0.2, 1.2}});  // a static box
		const mrpt::poses::CPose3D T(-1, 0.3, 1.2, 0.2, 0.1, 0);
		const int N = 5;
		size_t hit = 0, flagged = 0;
		for (int f = 0; f < N + 10; ++f)
		{
			const auto& r =
			    mg.processFrame(*renderScan(scene, T, W, H, 70, f), T, nullptr);
			if (f >= N)
			{
				hit += r.hitVoxels;
				flagged += r.movingTier1;
			}
		}
		ASSERT_GT(hit, 1000u);
		EXPECT_LT(double(flagged) / hit, 0.01) << bims::choiceName(mode);
	}
}

TEST(Scenes, BoxMovingIntoFreeSpaceIsFlagged)
{
	for (auto mode : {DecayMode::All, DecayMode::Frustum, DecayMode::Raycast})
	{
		GridParams p = test::paperGrids();
		p.decay = mode;
		MotionGrids mg(p);
		const auto scene = room();
		const mrpt::poses::CPose3D T(-2, 0, 1.2, 0, 0, 0);
		for (int f = 0; f < 6; ++f)
			mg.processFrame(*renderScan(scene, T, W, H, 70, f), T, nullptr);
		// A box enters the empty space between camera and wall, jumping 0.5 m
		// (more than its width) per frame, so that each frame it occupies
		// cells that were free: its pixels must be flagged, the wall's not.
		// (A box sliding within its own face plane re-hits the same cells,
		// which the model rightly turns into background after 3 frames.)
		for (int f = 6; f < 10; ++f)
		{
			auto s = scene;
			const double y = -1.5 + 0.5 * (f - 6);
			const Box box{{0.5, y, 0.5}, {0.8, y + 0.4, 1.6}};
			s.push_back(box);
			auto scan = renderScan(s, T, W, H, 70, f);
			auto bg = renderScan(scene, T, W, H, 70, f);
			const auto& r = mg.processFrame(*scan, T, nullptr);
			size_t boxPx = 0, boxFlagged = 0, restPx = 0, restFlagged = 0;
			for (int v = 0; v < H; ++v)
				for (int u = 0; u < W; ++u)
				{
					if (scan->rangeImage(v, u) == 0) continue;
					const bool isBox =
					    scan->rangeImage(v, u) != bg->rangeImage(v, u);
					const bool fl =
					    r.maskTier1().data[size_t(v) * W + u] == 255;
					(isBox ? boxPx : restPx)++;
					(isBox ? boxFlagged : restFlagged) += fl;
				}
			ASSERT_GT(boxPx, 50u);
			EXPECT_GT(double(boxFlagged) / boxPx, 0.9)
			    << bims::choiceName(mode) << " f" << f;
			EXPECT_LT(double(restFlagged) / restPx, 0.01)
			    << bims::choiceName(mode) << " f" << f;
			EXPECT_GT(r.movingTier1, 0u);
		}
	}
}

TEST(Scenes, RaycastRemembersAStaticObjectThatLeftTheView)
{
	const mrpt::math::TPoint3D onBox(1.53, 0.0, 0.8);  // front face of the box
	double pAfter[3] = {0, 0, 0};
	int i = 0;
	for (auto mode : {DecayMode::All, DecayMode::Frustum, DecayMode::Raycast})
	{
		GridParams p = test::paperGrids();
		p.decay = mode;
		MotionGrids mg(p);
		auto scene = room();
		scene.push_back({{1.52, -0.3, 0}, {1.9, 0.3, 1.5}});
		for (int f = 0; f < 5; ++f)
		{
			const mrpt::poses::CPose3D T(0, 0, 1, 0, 0, 0);  // looking at it
			mg.processFrame(*renderScan(scene, T, W, H, 60, f), T, nullptr);
		}
		EXPECT_GT(mg.occupancy()->probabilityAt(onBox), 0.9);
		for (int f = 5; f < 25; ++f)
		{
			// turn away: the box leaves the field of view
			const mrpt::poses::CPose3D T(0, 0, 1, M_PI, 0, 0);
			mg.processFrame(*renderScan(scene, T, W, H, 60, f), T, nullptr);
		}
		pAfter[i++] = mg.occupancy()->probabilityAt(onBox);
	}
	EXPECT_NEAR(pAfter[0], 0.12, 1e-3);  // all: forgotten (p_min)
	EXPECT_GT(pAfter[1], 0.9);           // frustum: remembered
	EXPECT_GT(pAfter[2], 0.9);           // raycast: remembered
}
