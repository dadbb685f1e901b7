// The fast paths of the grids against their plain definitions: a
// FrameCloud's cells are the distinct voxels of its readings in block order.
#include <bims/maps/frame_cloud.h>

#include <gtest/gtest.h>

#include <map>
#include <random>
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
