// Tier 0 properties: closed form applied once per frame, saturation, exact
// decay, lazy == eager bit for bit, ray casting and frustum decay.
#include <bims/maps/COccupancyBayesGrid.h>
#include <bims/maps/closed_form.h>

#include <gtest/gtest.h>

#include <map>
#include <random>

#include "scene_raycaster.h"
#include "test_util.h"

using namespace bims::maps;
using bims::maps::test::frameAt;

TEST(OccupancyGrid, OneFrameAppliesTheClosedFormOncePerVoxel)
{
	GridParams p = test::paperGrids();
	p.reading_lambda = 3;  // so that the count n matters
	COccupancyBayesGrid g(p);
	const VoxelKey k{3, -2, 5};
	g.integrate(frameAt(p, {k}, {4}));
	const double want = std::min(
	    occupancyPosterior(0, p.p_miss, std::log(3.0), 4), logit(p.p_max));
	EXPECT_NEAR(fromFixed(g.logOddsFixed(k)), want, 1e-6);
	// n readings are one update with hit(n), not n updates with hit(1).
	GridParams p2 = p;
	p2.p_max = 0.99999;
	COccupancyBayesGrid g2(p2);
	g2.integrate(frameAt(p2, {k}, {2}));
	EXPECT_NEAR(fromFixed(g2.logOddsFixed(k)),
	            hitLogOdds(p.p_miss, std::log(3.0), 2), 1e-6);
}

TEST(OccupancyGrid, HitEveryFrameSaturatesAtLmax)
{
	GridParams p = test::paperGrids();
	COccupancyBayesGrid g(p);
	const VoxelKey k{0, 0, 0};
	for (int f = 0; f < 10; ++f) g.integrate(frameAt(p, {k}, {1}));
	EXPECT_EQ(g.logOddsFixed(k), g.maxFixed());
	EXPECT_NEAR(g.probabilityAt(g.centerOf(k)), p.p_max, 1e-6);
}

TEST(OccupancyGrid, NeverHitDecaysByExactlyLog2MinusPmissPerFrame)
{
	GridParams p = test::paperGrids();  // decay = all
	p.p_min = 0.001;                    // room for many steps
	COccupancyBayesGrid g(p);
	EXPECT_NEAR(fromFixed(g.missFixed()), std::log(2 - p.p_miss), 1e-6);
	const VoxelKey far{100, 100, 100}, other{0, 0, 0};
	LogOddsFx prev = g.logOddsFixed(far);
	EXPECT_EQ(prev, 0);  // prior 0.5
	for (int f = 0; f < 30; ++f)
	{
		g.integrate(frameAt(p, {other}, {1}));
		const LogOddsFx now = g.logOddsFixed(far);
		EXPECT_EQ(now, std::max(prev - g.missFixed(), g.minFixed()));
		prev = now;
	}
	EXPECT_EQ(prev, g.minFixed());
}

TEST(OccupancyGrid, LazyDecayEqualsEagerDecayBitForBit)
{
	GridParams p = test::paperGrids();
	p.reading_lambda = 1.7;
	COccupancyBayesGrid g(p);
	std::mt19937 r(42);
	std::vector<VoxelKey> universe;
	for (int i = 0; i < 60; ++i)
		universe.push_back(
		    {int32_t(r() % 20) - 10, int32_t(r() % 20) - 10, int32_t(r() % 3)});
	std::map<uint64_t, LogOddsFx> eager;  // every key, updated every frame
	for (const auto& k : universe) eager[packKey(k)] = 0;
	for (int f = 0; f < 200; ++f)
	{
		std::vector<VoxelKey> hit;
		std::vector<uint32_t> n;
		std::map<uint64_t, uint32_t> hitN;
		// long gaps: hit rarely, with bursts
		const int m = (f % 37 < 5) ? int(r() % 12) : int(r() % 2);
		for (int i = 0; i < m; ++i)
		{
			const auto& k = universe[r() % universe.size()];
			if (hitN.count(packKey(k))) continue;
			const uint32_t c = 1 + r() % 6;
			hit.push_back(k);
			n.push_back(c);
			hitN[packKey(k)] = c;
		}
		g.integrate(frameAt(p, hit, n));
		for (auto& [key, v] : eager)
		{
			auto it = hitN.find(key);
			if (it != hitN.end())
				v = LogOddsFx(std::min<int64_t>(
				    int64_t(v) + g.hitFixed(it->second), g.maxFixed()));
			else
				v = std::max(v - g.missFixed(), g.minFixed());
		}
		for (const auto& [key, v] : eager)
			ASSERT_EQ(g.logOddsFixed(unpackKey(key)), v) << "frame " << f;
	}
}

TEST(OccupancyGrid, RaycastFreesBeforeTheHitAndNothingBehindIt)
{
	GridParams p = test::paperGrids();
	p.decay = DecayMode::Raycast;
	p.raycast_margin = 0;  // the free space reaches the hit voxel
	COccupancyBayesGrid g(p);
	// Sensor in voxel (0,0,0), readings at voxels 20 and 30 along x.
	const mrpt::math::TPoint3D o(0.025, 0.025, 0.025);
	g.integrate(frameAt(p, {{20, 0, 0}, {30, 0, 0}}, {1, 1}, o));
	const LogOddsFx hit = g.hitFixed(1), miss = -g.missFixed();
	for (int x = 0; x < 20; ++x)
		EXPECT_EQ(g.logOddsFixed({x, 0, 0}), miss) << x;
	// The near hit is traversed by the far ray: hits win over misses.
	EXPECT_EQ(g.logOddsFixed({20, 0, 0}), hit);
	for (int x = 21; x < 30; ++x) EXPECT_EQ(g.logOddsFixed({x, 0, 0}), miss);
	EXPECT_EQ(g.logOddsFixed({30, 0, 0}), hit);
	for (int x = 31; x < 40; ++x) EXPECT_EQ(g.logOddsFixed({x, 0, 0}), 0);
	EXPECT_EQ(g.logOddsFixed({10, 1, 0}), 0);  // off the ray: untouched
	// No lazy decay in this mode: untouched cells keep their belief.
	for (int f = 0; f < 5; ++f) g.integrate(frameAt(p, {}, {}, o));
	EXPECT_EQ(g.logOddsFixed({30, 0, 0}), hit);
}

// raycast_margin: the inverse sensor model's free region ends the margin
// before the reading (r < z - alpha/2): the voxels in that band keep their
// belief; a ray not longer than the margin frees nothing.
TEST(OccupancyGrid, RaycastMarginLeavesTheReadingsNoiseBandUnmissed)
{
	GridParams p = test::paperGrids();
	p.decay = DecayMode::Raycast;
	p.voxel_size = 0.05;
	p.raycast_margin = 0.1;  // two voxels
	COccupancyBayesGrid g(p);
	const mrpt::math::TPoint3D o(0.025, 0.025, 0.025);
	// Readings at the centres of voxels 20 (along x) and 1 (along y): the
	// first ray ends at x = 1.025 - 0.1 = 0.925 m, in voxel 18.
	g.integrate(frameAt(p, {{20, 0, 0}, {0, 1, 0}}, {1, 1}, o));
	const LogOddsFx hit = g.hitFixed(1), miss = -g.missFixed();
	for (int x = 1; x <= 17; ++x)
		EXPECT_EQ(g.logOddsFixed({x, 0, 0}), miss) << x;
	EXPECT_EQ(g.logOddsFixed({18, 0, 0}), 0);
	EXPECT_EQ(g.logOddsFixed({19, 0, 0}), 0);
	EXPECT_EQ(g.logOddsFixed({20, 0, 0}), hit);
	// The sensor's own voxel is crossed by the long ray only.
	EXPECT_EQ(g.logOddsFixed({0, 0, 0}), miss);
	EXPECT_EQ(g.logOddsFixed({0, 1, 0}), hit);
	// Without the margin the band is missed as well.
	p.raycast_margin = 0;
	COccupancyBayesGrid h(p);
	h.integrate(frameAt(p, {{20, 0, 0}}, {1}, o));
	EXPECT_EQ(h.logOddsFixed({18, 0, 0}), miss);
	EXPECT_EQ(h.logOddsFixed({19, 0, 0}), miss);
}

TEST(OccupancyGrid, RaycastDiagonalRayIsSixConnected)
{
	GridParams p = test::paperGrids();
	p.decay = DecayMode::Raycast;
	p.raycast_margin = 0;  // the free space reaches the hit voxel
	COccupancyBayesGrid g(p);
	const mrpt::math::TPoint3D o(0.01, 0.02, 0.03);
	const VoxelKey end{17, -9, 6};
	g.integrate(frameAt(p, {end}, {1}, o));
	size_t freed = 0;
	g.storage().forEachCell([&](const VoxelKey&, const auto& c)
	                        { freed += c.stamp == 1 && c.l < 0; });
	// A 6-connected traversal crosses |dx|+|dy|+|dz| voxel faces.
	EXPECT_EQ(freed, size_t(17 + 9 + 6));
}

TEST(OccupancyGrid, FrustumDecaysOnlyInViewAndInFrontOfDepth)
{
	using namespace bims::maps::test;
	GridParams p = test::paperGrids();
	p.decay = DecayMode::Frustum;
	p.voxel_size = 0.1;
	COccupancyBayesGrid g(p);
	// A wall at x = 3 seen from the origin looking along +x.
	std::vector<Box> scene = {{{3, -5, -5}, {3.2, 5, 5}}};
	const mrpt::poses::CPose3D T_WS(0, 0, 0, 0, 0, 0);
	FrameCloudBuilder b(p);
	// Seed three cells with a hit each: in front of the wall (in view),
	// behind the wall (in view), and behind the camera (out of view).
	const VoxelKey front{15, 0, 0}, behind{35, 0, 0}, back{-10, 0, 0};
	g.integrate(frameAt(p, {front, behind, back}, {1, 1, 1}, {0, 0, 0}, 1));
	const LogOddsFx seeded = g.logOddsFixed(front);
	FrameCloud f;
	b.build(*renderScan(scene, T_WS, 64, 48, 60, 2), T_WS, f);
	g.integrate(f);
	EXPECT_EQ(g.logOddsFixed(front), seeded - g.missFixed());
	EXPECT_EQ(g.logOddsFixed(behind), seeded);
	EXPECT_EQ(g.logOddsFixed(back), seeded);
	EXPECT_GT(g.probabilityAt({3.05, 0.0, 0.0}), 0.5);  // the wall itself
}
