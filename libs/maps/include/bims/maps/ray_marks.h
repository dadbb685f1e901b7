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
/** The end of a ray, in voxel units. */
struct RayEnd
{
	double p[3];
};

/** The rays' bounding box in blocks of 8^3 voxels, and the layout of its
 * voxel bitset: the bit index of a voxel holds its cell index in its block
 * (bits 0-8: x, y, z three bits each, the cells' order in a block) and
 * above them the block's place in the box in Morton order (the box padded
 * to powers of two blocks per axis). So a block's 512 bits are one 64-byte
 * cache line, a word is one row z of a block, neighbouring blocks are near
 * in memory, and a step of the DDA along an axis is an addition on that
 * axis's bits only (step()). */
struct RayBox
{
	int32_t lo[3] = {};     // first block per axis
	unsigned logN[3] = {};  // log2 of the padded blocks per axis
	uint64_t mask[3] = {};  // the bits of the bit index holding each axis

	/** The box of blocks [lo, hi] (inclusive). */
	RayBox(const int32_t lo[3], const int32_t hi[3]);
	/** The box of the rays from \a a (voxel units) to \a ends, with one
	 * block of margin (a DDA may round one voxel past its end on an axis). */
	static RayBox around(const double a[3], const RayEnd* ends, size_t n);

	/** Blocks of the padded box (bit index >> 9 is below this). */
	size_t blocks() const { return size_t(1) << (logN[0] + logN[1] + logN[2]); }
	size_t words() const { return blocks() * 8; }
	/** Bit of the voxel (x, y, z) (absolute voxel indices, in the box). */
	uint64_t bitOf(int32_t x, int32_t y, int32_t z) const;
	/** Block (bx, by, bz) (absolute block indices, in the box). */
	size_t blockOf(int32_t bx, int32_t by, int32_t bz) const
	{
		return size_t(bitOf(bx * 8, by * 8, bz * 8) >> 9);
	}
	/** The absolute block indices of block \a b. */
	void blockCoords(size_t b, int32_t out[3]) const;
	/** The bit index one voxel along the axis of \a m from \a g, in the
	 * direction of \a c (c = -m: +1, c = -1: -1; m = c = 0: no move). */
	static uint64_t step(uint64_t g, uint64_t m, uint64_t c)
	{
		return (((g & m) + c) & m) | (g & ~m);
	}
};

/** The marks of the rays one thread walked: a "crossed" bit per voxel; per
 * block whether it was looked up and is stored and, if it is missing, the
 * earliest visit (ray << 32 | step) by the rays of this thread. Only the blocks
 * in touched (looked up, in the order of looking up) have crossed bits or
 * state; reset() clears just them, so a frame costs what its rays touch. */
struct RayMarks
{
	enum : uint8_t
	{
		kUnknown = 0,  // not looked up
		kMissing = 1,  // looked up, not stored
		kStored = 2,   // looked up, stored
	};
	std::vector<uint64_t> bits;        // 8 words per block
	std::vector<uint8_t> state;        // per block
	std::vector<uint64_t> firstVisit;  // per block, valid if kMissing
	std::vector<uint32_t> touched;     // blocks looked up

	/** Nothing crossed, no block looked up. */
	void reset(const RayBox& box);
	bool missing(size_t b) const { return state[b] == kMissing; }
	bool stored(size_t b) const { return state[b] == kStored; }
};

/** Is the block (bx, by, bz) (absolute block indices) stored? */
using BlockStored = bool (*)(const void* ctx, int32_t bx, int32_t by,
                             int32_t bz);

/** How many rays a walker steps at once, in the lanes of which registers. */
enum class RayLanes
{
	Best,   // the widest this CPU runs
	One,    // one at a time, in scalars (any CPU)
	Four,   // AVX2
	Eight,  // AVX-512
};
/** Can this CPU run \a lanes? */
bool rayLanesSupported(RayLanes lanes);

/** Walks rays [r0, r1) of \a ends from \a a (voxel units), with the DDA of
 * traverseRay() (the same voxels, step by step), and marks every voxel
 * they cross in \a m (reset for \a box before the first call; rays may be
 * split over calls and threads in any way: the marks of the parts, merged
 * with mergeRayMarks(), are the same, and so for every \a lanes; lanes
 * this CPU cannot run fall back to Best). Each block the rays enter
 * is looked up once with \a stored; the blocks not stored keep their earliest
 * visit (ray, step). Single-threaded per RayMarks. */
void markRays(const double a[3], const RayEnd* ends, size_t r0, size_t r1,
              const RayBox& box, BlockStored stored, const void* ctx,
              RayMarks& m, RayLanes lanes = RayLanes::Best);

/** Merges \a other into \a m: crossed bits or-ed, blocks looked up by
 * either, earliest visits. (Call before applying, not before walking more
 * rays into \a m.) */
void mergeRayMarks(RayMarks& m, const RayMarks& other);

}  // namespace bims::maps
