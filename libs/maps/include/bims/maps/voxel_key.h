// Integer voxel coordinates and their packing into 64-bit hash keys.
#pragma once

#include <cmath>
#include <cstdint>

namespace bims::maps
{
/** Integer coordinates of a voxel: the cell [i s, (i+1) s) on each axis of
 * {W} for voxel size s (the same convention as OctoMap's keys). */
struct VoxelKey
{
	int32_t x = 0, y = 0, z = 0;
	bool operator==(const VoxelKey& o) const
	{
		return x == o.x && y == o.y && z == o.z;
	}
	bool operator!=(const VoxelKey& o) const { return !(*this == o); }
};

/** Largest |coordinate| that packKey() accepts (21 bits per axis). */
constexpr int32_t kMaxKeyCoord = (1 << 20) - 1;

/** Packs three signed 21-bit coordinates into one 64-bit key (never
 * ~0ull, the empty marker of FlatHashMap). Precondition:
 * |x|,|y|,|z| <= kMaxKeyCoord. */
inline uint64_t packKey(int32_t x, int32_t y, int32_t z)
{
	constexpr int64_t o = 1 << 20;
	return (uint64_t(x + o) << 42) | (uint64_t(y + o) << 21) | uint64_t(z + o);
}
inline uint64_t packKey(const VoxelKey& k)
{
	return packKey(k.x, k.y, k.z);
}
inline VoxelKey unpackKey(uint64_t p)
{
	constexpr int64_t o = 1 << 20;
	constexpr uint64_t m = (1u << 21) - 1;
	return {int32_t(int64_t((p >> 42) & m) - o),
	        int32_t(int64_t((p >> 21) & m) - o), int32_t(int64_t(p & m) - o)};
}

/** Voxel index of a coordinate [m] for voxel size \a res: floor(v / res). */
inline int32_t coordToIndex(double v, double invRes)
{
	return static_cast<int32_t>(std::floor(v * invRes));
}

}  // namespace bims::maps
