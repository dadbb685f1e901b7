// The fast paths of the grids against their plain definitions: a
// FrameCloud's cells are the distinct voxels of its readings in block order;
// the raycast decay equals a per-voxel DDA on a std::map.
#include <bims/maps/COccupancyBayesGrid.h>
#include <bims/maps/dda.h>
#include <bims/maps/frame_cloud.h>

#include <gtest/gtest.h>

#include "scene_raycaster.h"

#include <map>
#include <random>
#include <set>
#include <tuple>
#include <vector>

using namespace bims::maps;

TEST(FrameCloud, CellsAreTheDistinctVoxelsOfTheReadingsInBlockOrder)
{
	for (double voxel : {0.02, 0.05, 0.3})
	{
		GridParams p;
		p.voxel_size = voxel;
		p.max_range = 6;
		std::mt19937 rng(3);
		std::normal_distribution<float> N(0, 2);
		std::vector<mrpt::math::TPoint3Df> pts;
		for (int i = 0; i < 20000; ++i)
		{
			// Clustered readings (many per voxel), some beyond max_range.
			const float x = N(rng), y = N(rng), z = N(rng);
			for (int j = 0; j < 3; ++j)
				pts.emplace_back(x + 0.004f * j, y, z - 0.003f * j);
		}
		pts.emplace_back(NAN, 0.f, 0.f);
		const mrpt::math::TPoint3D origin(0.3, -0.2, 0.1);
		FrameCloudBuilder b(p);
		FrameCloud f;
		b.buildFromPoints(pts, {}, origin, f);
		ASSERT_EQ(f.stats.nonFinite, 1u);
		ASSERT_GT(f.stats.beyondRange, 0u);
		ASSERT_EQ(f.numPoints() + f.stats.skipped(), pts.size());
		// Reference: voxel of each kept reading, counted in a std::map.
		auto keyOf = [&](const mrpt::math::TPoint3Df& q)
		{
			const double inv = 1 / voxel;
			return VoxelKey{coordToIndex(q.x, inv), coordToIndex(q.y, inv),
			                coordToIndex(q.z, inv)};
		};
		auto order = [](const VoxelKey& k)
		{
			return std::make_tuple(k.x >> 3, k.y >> 3, k.z >> 3, k.z & 7,
			                       k.y & 7, k.x & 7);
		};
		std::map<decltype(order(VoxelKey())), uint32_t> ref;
		for (size_t i = 0; i < f.numPoints(); ++i)
		{
			const VoxelKey k = keyOf(f.points_W[i]);
			ref[order(k)]++;
			ASSERT_LT(f.cellOfPoint[i], f.numCells());
			ASSERT_EQ(f.cells[f.cellOfPoint[i]], k) << "reading " << i;
		}
		ASSERT_EQ(f.numCells(), ref.size());
		size_t c = 0;
		for (const auto& [o, n] : ref)
		{
			EXPECT_EQ(order(f.cells[c]), o) << "cell " << c;
			EXPECT_EQ(f.hits[c], n) << "cell " << c;
			++c;
		}
	}
}

// decay = raycast (ray ends in tile order, the per-frame block table, with
// 1 or 2 threads) against a plain per-voxel reference: a std::map updated
// along traverseRay() from the sensor origin to each reading.
TEST(Raycast, SameResultAsAPlainDdaOnAMapWithAnyThreadCount)
{
	auto scene = bims::maps::test::room();
	scene.push_back({{1.0, -0.6, 0}, {1.6, 0.4, 1.4}});
	const mrpt::poses::CPose3D poses[] = {{-1, 0.3, 1.2, 0.2, 0.1, 0},
	                                      {-0.5, -0.4, 1.0, -0.6, 0.0, 0.1},
	                                      {-1, 0.3, 1.2, 2.0, -0.2, 0}};
	GridParams p;
	p.decay = DecayMode::Raycast;
	p.voxel_size = 0.04;
	COccupancyBayesGrid g1(p);
	p.raycast_threads = 2;
	COccupancyBayesGrid g2(p);
	FrameCloudBuilder b(p);
	std::map<std::tuple<int, int, int>, LogOddsFx> ref;
	for (int f = 0; f < 3; ++f)
	{
		const auto scan =
		    bims::maps::test::renderScan(scene, poses[f], 100, 75, 70, f);
		FrameCloud fc;
		b.build(*scan, poses[f], fc);
		ASSERT_GT(fc.numPoints(), 5000u);  // > 2 work items of rays
		g1.integrate(fc);
		g2.integrate(fc);
		// Reference: hits first, then one miss per voxel crossed.
		std::set<std::tuple<int, int, int>> touched;
		for (size_t i = 0; i < fc.numCells(); ++i)
		{
			const auto& k = fc.cells[i];
			auto& l = ref[{k.x, k.y, k.z}];
			l = LogOddsFx(std::min<int64_t>(
			    int64_t(l) + g1.hitFixed(fc.hits[i]), g1.maxFixed()));
			touched.insert({k.x, k.y, k.z});
		}
		const double inv = 1 / p.voxel_size;
		const double a[3] = {fc.origin_W.x * inv, fc.origin_W.y * inv,
		                     fc.origin_W.z * inv};
		for (const auto& q : fc.points_W)
		{
			const double e[3] = {q.x * inv, q.y * inv, q.z * inv};
			traverseRay(a, e,
			            [&](int32_t x, int32_t y, int32_t z)
			            {
				            if (!touched.insert({x, y, z}).second) return;
				            auto& l = ref[{x, y, z}];
				            l = std::max<LogOddsFx>(l - g1.missFixed(),
				                                    g1.minFixed());
			            });
		}
	}
	size_t compared = 0;
	for (const auto& [k, l] : ref)
	{
		const VoxelKey key{std::get<0>(k), std::get<1>(k), std::get<2>(k)};
		ASSERT_EQ(g1.logOddsFixed(key), l);
		ASSERT_EQ(g2.logOddsFixed(key), l);
		++compared;
	}
	// Nothing else was touched: as many stored cells with a stamp.
	for (const auto* g : {&g1, &g2})
	{
		size_t stamped = 0;
		g->storage().forEachCell([&](const VoxelKey&, const auto& c)
		                         { stamped += c.stamp != 0; });
		EXPECT_EQ(stamped, compared);
	}
	EXPECT_GT(compared, 20000u);
}
