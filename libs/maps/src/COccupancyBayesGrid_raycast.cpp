// Tier 0: the miss update for decay = raycast (docs/maps.md, "Decay
// modes"). The model: every voxel that the DDA of traverseRay() crosses
// from the sensor origin to a reading, not hit in this frame, gets one
// miss. The hits are applied first (COccupancyBayesGrid::applyFrame) and
// stamped, so that which ray crosses a voxel, how often, and in which order
// does not matter for its value. What the order of the rays does decide is
// the order in which missing blocks are created (the order of the storage)
// and, over the memory budget, which ones: that order is the one of a plain
// walk, ray after ray, step after step.
//
// The fast path (castMarked): the rays are walked once, marking the voxels
// they cross in a per-frame bitset of the rays' bounding box (no cell is
// read or written during the walk, so any number of threads can walk); the
// missing blocks the rays enter are then created in the order of their
// first visit (ray, step), and each crossed cell gets its miss once, block
// row by block row.
#include <bims/maps/COccupancyBayesGrid.h>
#include <bims/maps/dda.h>
#include <bims/maps/ray_marks.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <thread>
#include <utility>

namespace bims::maps
{
namespace
{
// Rays are cast tile by tile of the image (kTile x kTile pixels): the rays
// of a tile cross nearly the same voxels, which then stay in cache.
constexpr int kTile = 8;
// Largest bounding box of the rays for the bitsets (voxels of the box
// padded to powers of two blocks per axis, one bit each per thread: 32 MiB,
// of which a frame touches only the blocks its rays enter); beyond it (huge
// extents at fine voxels) the rays are walked voxel by voxel (castPlain).
constexpr size_t kMaxMarkedVoxels = size_t(1) << 28;
// Rays per work item of a thread (32 tiles).
constexpr size_t kChunk = 2048;

// castMarked()'s walk: the rays of \a ends from \a a marked in \a marks
// (one per thread, \a threads of them; crossed voxels, blocks stored or
// not, first visits), merged into the first, which is returned.
template <class Storage>
RayMarks& walkRays(const double a[3], const std::vector<RayEnd>& ends,
                   const RayBox& box, size_t threads, const Storage& grid,
                   std::vector<RayMarks>& marks)
{
	marks.resize(threads);
	const BlockStored stored =
	    [](const void* g, int32_t bx, int32_t by, int32_t bz)
	{
		return static_cast<const Storage*>(g)->findBlock(packKey(bx, by, bz)) !=
		       nullptr;
	};
	std::atomic<size_t> next{0};
	auto worker = [&](size_t t)
	{
		RayMarks& m = marks[t];
		m.reset(box);
		for (;;)
		{
			const size_t r0 = next.fetch_add(kChunk);
			if (r0 >= ends.size()) break;
			markRays(a, ends.data(), r0, std::min(ends.size(), r0 + kChunk),
			         box, stored, &grid, m);
		}
	};
	if (threads == 1)
		worker(0);
	else
	{
		std::vector<std::thread> pool;
		for (size_t t = 1; t < threads; ++t) pool.emplace_back(worker, t);
		worker(0);
		for (auto& th : pool) th.join();
	}
	RayMarks& m = marks[0];
	for (size_t t = 1; t < threads; ++t) mergeRayMarks(m, marks[t]);
	return m;
}

// The cells of each block \a m entered (into \a cells, one entry per
// m.touched); the missing blocks created in the order of their first
// visit, as a plain walk creates them. Returns whether the memory budget
// left one uncreated (its state then kUnknown).
template <class Cell, class Storage>
bool cellsOfTouchedBlocks(RayMarks& m, const RayBox& box, Storage& grid,
                          std::vector<Cell*>& cells)
{
	cells.assign(m.touched.size(), nullptr);
	std::vector<std::pair<uint64_t, size_t>> missing;
	auto keyOf = [&](size_t b)
	{
		int32_t c[3];
		box.blockCoords(b, c);
		return packKey(c[0], c[1], c[2]);
	};
	for (size_t i = 0; i < m.touched.size(); ++i)
	{
		const size_t b = m.touched[i];
		if (m.stored(b))
			cells[i] = grid.findBlock(keyOf(b))->cells;
		else
			missing.emplace_back(m.firstVisit[b], i);
	}
	std::sort(missing.begin(), missing.end());
	bool budgetHit = false;
	for (const auto& [visit, i] : missing)
	{
		const uint32_t id = grid.findOrCreateBlock(keyOf(m.touched[i]));
		if (id == FlatHashMap::kNotFound)
		{
			budgetHit = true;
			m.state[m.touched[i]] = RayMarks::kUnknown;  // not created
		}
		else
			cells[i] = grid.block(id).cells;
	}
	return budgetHit;
}

// Over the budget: the steps into blocks that could not be created, as a
// plain walk counts them (every step).
size_t stepsIntoUncreatedBlocks(const double a[3],
                                const std::vector<RayEnd>& ends,
                                const RayMarks& m, const RayBox& box)
{
	size_t over = 0;
	for (const auto& e : ends)
		traverseRay(a, e.p,
		            [&](int32_t x, int32_t y, int32_t z)
		            {
			            over += m.state[box.blockOf(x >> 3, y >> 3, z >> 3)] ==
			                    RayMarks::kUnknown;
		            });
	return over;
}
}  // namespace

void COccupancyBayesGrid::collectRayEnds(const FrameCloud& f, double inv)
{
	auto& ends = rayEnds_;
	ends.clear();
	const int dec = params_.raycast_decimation;
	if (params_.raycast_target == RayTarget::Voxels)
	{
		for (size_t i = 0; i < f.cells.size(); ++i)
		{
			if (dec > 1 && i % size_t(dec * dec) != 0) continue;
			const auto& k = f.cells[i];
			ends.push_back({{k.x + 0.5, k.y + 0.5, k.z + 0.5}});
		}
		return;
	}
	const int W = f.K.width, H = f.K.height;
	const bool organised = W > 0 && H > 0;
	auto keep = [&](size_t i)
	{
		if (dec <= 1) return true;
		if (!organised) return i % size_t(dec) == 0;
		const uint32_t px = f.pixel[i];
		return (px % W) % dec == 0 && (px / W) % dec == 0;
	};
	auto end = [&](size_t i)
	{
		const auto& p = f.points_W[i];
		return RayEnd{{p.x * inv, p.y * inv, p.z * inv}};
	};
	if (!organised)
	{
		for (size_t i = 0; i < f.points_W.size(); ++i)
			if (keep(i)) ends.push_back(end(i));
		return;
	}
	// Counting sort of the readings by tile.
	const int tw = (W + kTile - 1) / kTile, th = (H + kTile - 1) / kTile;
	auto& start = tileStart_;
	start.assign(size_t(tw) * th + 1, 0);
	auto tileOf = [&](uint32_t px)
	{ return (px / W / kTile) * tw + (px % W) / kTile; };
	for (size_t i = 0; i < f.points_W.size(); ++i)
		if (keep(i)) start[tileOf(f.pixel[i]) + 1]++;
	for (size_t t = 1; t < start.size(); ++t) start[t] += start[t - 1];
	ends.resize(start.back());
	for (size_t i = 0; i < f.points_W.size(); ++i)
		if (keep(i)) ends[start[tileOf(f.pixel[i])]++] = end(i);
}

void COccupancyBayesGrid::decayRaycast(const FrameCloud& f, uint32_t F)
{
	const double inv = 1 / params_.voxel_size;
	const auto& o = f.origin_W;
	const double ext = params_.extent;
	if (std::abs(o.x) > ext || std::abs(o.y) > ext || std::abs(o.z) > ext)
	{
		FrameStats st;
		st.outsideExtent = f.points_W.size();
		accountFrame(st);
		return;  // keys along the rays could leave the key range
	}
	const double a[3] = {o.x * inv, o.y * inv, o.z * inv};
	collectRayEnds(f, inv);
	// The readings' noise band (raycast_margin): each ray ends that far
	// before its reading (in voxel units); a ray no longer than it is not
	// cast.
	if (const double margin = params_.raycast_margin * inv; margin > 0)
	{
		size_t w = 0;
		for (const RayEnd& e : rayEnds_)
		{
			const double d[3] = {e.p[0] - a[0], e.p[1] - a[1], e.p[2] - a[2]};
			const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
			if (n <= margin) continue;
			const double k = (n - margin) / n;
			rayEnds_[w++] = {
			    {a[0] + k * d[0], a[1] + k * d[1], a[2] + k * d[2]}};
		}
		rayEnds_.resize(w);
	}
	if (rayEnds_.empty()) return;

	const RayBox box = RayBox::around(a, rayEnds_.data(), rayEnds_.size());
	const size_t over = box.words() * 64 <= kMaxMarkedVoxels
	                        ? castMarked(a, box, F)
	                        : castPlain(a, F);
	if (over)
	{
		FrameStats st;
		st.overBudget = over;
		accountFrame(st);
	}
}

size_t COccupancyBayesGrid::castPlain(const double a[3], uint32_t F)
{
	size_t over = 0;
	Storage::Accessor acc(grid_);
	for (const auto& e : rayEnds_)
		traverseRay(a, e.p,
		            [&](int32_t x, int32_t y, int32_t z)
		            {
			            Cell* c = acc.get(x, y, z);
			            if (c)
				            applyMiss(*c, F);
			            else
				            ++over;
		            });
	return over;
}

size_t COccupancyBayesGrid::castMarked(const double a[3], const RayBox& box,
                                       uint32_t F)
{
	const auto& ends = rayEnds_;
	const size_t threads =
	    std::clamp<size_t>(size_t(params_.raycast_threads), 1,
	                       (ends.size() + kChunk - 1) / kChunk);
	// 1. The walk: crossed voxels, blocks stored or not, first visits.
	RayMarks& m = walkRays(a, ends, box, threads, grid_, rayMarks_);
	// 2. The cells of each block entered.
	const bool budgetHit = cellsOfTouchedBlocks(m, box, grid_, blockCells_);
	// 3. One miss per crossed cell.
	applyRayMarks(m, blockCells_.data(), F);
	return budgetHit ? stepsIntoUncreatedBlocks(a, ends, m, box) : 0;
}

void COccupancyBayesGrid::applyRayMarks(const RayMarks& m, Cell* const* cells,
                                        uint32_t F)
{
	// Word z of a block's bits is its row z of cells (cell z * 64 + bit).
	for (size_t i = 0; i < m.touched.size(); ++i)
	{
		Cell* blk = cells[i];
		if (!blk) continue;  // over the memory budget
		const uint64_t* w = &m.bits[8 * size_t(m.touched[i])];
		for (size_t z = 0; z < 8; ++z, blk += 64)
			for (uint64_t v = w[z]; v; v &= v - 1)
				applyMiss(blk[__builtin_ctzll(v)], F);
	}
}

}  // namespace bims::maps
