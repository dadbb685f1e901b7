// decay = raycast, the walk: which voxels the rays of a frame cross, marked
// in a per-frame bitset, and which blocks they enter first (docs/maps.md,
// "Decay modes"). Used by the tier-0 grid; public for the tests.
#pragma once

#include <bims/maps/dda.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace bims::maps
{
/** The rays' bounding box in blocks of 8^3 voxels, and the layout of its
 * voxel bitsets: one bit per voxel, x fastest, a row of voxels along x
 * padded to whole 64-bit words, so that a step of the DDA along x, y or z
 * adds a constant to the bit index (1, rowBits(), planeBits()). */
struct RayBox
{
	int32_t lo[3] = {};  // first block per axis
	size_t n[3] = {};    // blocks per axis
	size_t rowWords = 0;

	/** The box of blocks [lo, hi] (inclusive). */
	RayBox(const int32_t lo[3], const int32_t hi[3]);

	size_t blocks() const { return n[0] * n[1] * n[2]; }
	size_t rows() const { return n[1] * 8 * n[2] * 8; }
	size_t words() const { return rowWords * rows(); }
	uint64_t rowBits() const { return uint64_t(rowWords) * 64; }
	uint64_t planeBits() const { return rowBits() * n[1] * 8; }
	/** Bit of the voxel (x, y, z) (absolute voxel indices, in the box). */
	uint64_t bitOf(int32_t x, int32_t y, int32_t z) const
	{
		return uint64_t(x - lo[0] * 8) + rowBits() * uint64_t(y - lo[1] * 8) +
		       planeBits() * uint64_t(z - lo[2] * 8);
	}
	/** Index of the block (bx, by, bz) relative to lo, x fastest. */
	size_t blockIndex(size_t bx, size_t by, size_t bz) const
	{
		return bx + n[0] * (by + n[1] * bz);
	}
};

/** The marks of the rays one thread walked: per voxel a "crossed" bit and
 * an "unresolved" bit (its block not looked up yet, or looked up and not
 * stored), interleaved word by word so that one cache line holds both; per
 * block whether it is stored and, if it is not, the earliest visit
 * (ray << 32 | step) by the rays of this thread. */
struct RayMarks
{
	static constexpr uint64_t kNoVisit = ~uint64_t(0);
	enum : uint8_t
	{
		kUnknown = 0,
		kStored = 1,
		kMissing = 2
	};
	std::vector<uint64_t> bits;        // [2w]: crossed, [2w + 1]: unresolved
	std::vector<uint8_t> state;        // per block
	std::vector<uint64_t> firstVisit;  // per block, for kMissing blocks

	/** Nothing crossed, every voxel unresolved, no block looked up. */
	void reset(const RayBox& box);
};

/** The end of a ray, in voxel units. */
struct RayEnd
{
	double p[3];
};

/** Is the block (bx, by, bz) (absolute block indices) stored? */
using BlockStored = bool (*)(const void* ctx, int32_t bx, int32_t by,
                             int32_t bz);

/** Walks rays [r0, r1) of \a ends from \a a (voxel units), with the DDA of
 * traverseRay() (the same voxels, step by step), and marks every voxel
 * they cross in \a m (reset for \a box before the first call; rays may be
 * split over calls and threads in any way: the marks of the parts, merged
 * with mergeRayMarks(), are the same). The first visit of a voxel of a
 * block looks the block up with \a stored; visits of blocks not stored
 * keep their earliest (ray, step). Single-threaded per RayMarks. */
void markRays(const double a[3], const RayEnd* ends, size_t r0, size_t r1,
              const RayBox& box, BlockStored stored, const void* ctx,
              RayMarks& m);

/** Merges \a other into \a m: crossed bits or-ed, blocks looked up by
 * either, earliest visits. (The unresolved bits of \a m are left stale:
 * call before applying, not before walking more rays into \a m.) */
void mergeRayMarks(RayMarks& m, const RayMarks& other);

}  // namespace bims::maps
