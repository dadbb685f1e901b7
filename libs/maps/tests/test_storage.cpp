// Sparse voxel storage: hash map, block addressing, negative coordinates.
#include <bims/maps/flat_hash_map.h>
#include <bims/maps/sparse_voxel_grid.h>

#include <gtest/gtest.h>

#include <random>
#include <unordered_map>

using namespace bims::maps;

TEST(FlatHashMap, AgreesWithUnorderedMap)
{
	FlatHashMap m;
	std::unordered_map<uint64_t, uint32_t> ref;
	std::mt19937_64 g(7);
	for (int i = 0; i < 100000; ++i)
	{
		const uint64_t k = g() % 50000;
		const uint32_t v = uint32_t(g());
		auto [got, ins] = m.insert(k, v);
		auto [it, ins2] = ref.emplace(k, v);
		ASSERT_EQ(ins, ins2);
		ASSERT_EQ(got, it->second);
	}
	EXPECT_EQ(m.size(), ref.size());
	for (const auto& [k, v] : ref) ASSERT_EQ(m.find(k), v);
	EXPECT_EQ(m.find(123456789), FlatHashMap::kNotFound);
	m.clear();
	EXPECT_EQ(m.size(), 0u);
	EXPECT_EQ(m.find(ref.begin()->first), FlatHashMap::kNotFound);
}

TEST(VoxelKey, PackRoundTripIncludingNegatives)
{
	for (int32_t x : {-kMaxKeyCoord, -1, 0, 1, 12345, kMaxKeyCoord})
		for (int32_t y : {-7, 0, 999999})
			for (int32_t z : {-kMaxKeyCoord, 3})
			{
				const VoxelKey k{x, y, z};
				ASSERT_EQ(unpackKey(packKey(k)), k);
			}
	EXPECT_EQ(coordToIndex(-0.001, 1 / 0.05), -1);
	EXPECT_EQ(coordToIndex(0.0, 1 / 0.05), 0);
	EXPECT_EQ(coordToIndex(0.0999, 1 / 0.05), 1);
}

TEST(SparseVoxelGrid, CellsAreAddressedConsistently)
{
	struct C
	{
		int v = -1;
	};
	SparseVoxelGrid<C, 3> g;
	std::mt19937 r(3);
	std::vector<VoxelKey> keys;
	for (int i = 0; i < 2000; ++i)
	{
		VoxelKey k{int32_t(r() % 400) - 200, int32_t(r() % 400) - 200,
		           int32_t(r() % 40) - 20};
		keys.push_back(k);
		g.findOrCreate(k)->v = i;
	}
	for (int i = 0; i < 2000; ++i)
	{
		const C* c = g.find(keys[i]);
		ASSERT_NE(c, nullptr);
		// later writes to the same key win
		bool later = false;
		for (int j = i + 1; j < 2000; ++j) later |= keys[j] == keys[i];
		if (!later)
		{
			ASSERT_EQ(c->v, i);
		}
	}
	// cellKey() inverts the addressing.
	size_t seen = 0;
	g.forEachCell(
	    [&](const VoxelKey& k, const C& c)
	    {
		    if (c.v >= 0)
		    {
			    EXPECT_EQ(g.find(k), &c);
			    ++seen;
		    }
	    });
	EXPECT_GT(seen, 1900u);
	EXPECT_EQ(g.find(VoxelKey{100000, 0, 0}), nullptr);
}

TEST(SparseVoxelGrid, RespectsMemoryBudget)
{
	struct C
	{
		float v = 0;
	};
	SparseVoxelGrid<C, 3> g(64 * 1024);
	size_t made = 0;
	for (int i = 0; i < 1000; ++i)
		made += g.findOrCreate(VoxelKey{i * 8, 0, 0}) != nullptr;
	EXPECT_LT(made, 1000u);
	EXPECT_LE(g.memoryBytes(), 64u * 1024u);
}
