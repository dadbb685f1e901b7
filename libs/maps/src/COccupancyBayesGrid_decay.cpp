// Tier 0: the miss update for decay = frustum and decay = raycast.
#include <bims/maps/COccupancyBayesGrid.h>
#include <bims/maps/dda.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <thread>
#include <type_traits>

// The two-lane ray walk needs SSE2 and 64-bit integer moves (x86-64).
#if defined(__SSE2__) && defined(__x86_64__)
#define BIMS_RAYCAST_SSE2 1
#include <emmintrin.h>
#endif

namespace bims::maps
{

namespace
{
// Rays are cast tile by tile of the image (kTile x kTile pixels): the rays
// of a tile cross nearly the same voxels, which then stay in cache.
constexpr int kTile = 8;
// Largest per-frame table of block pointers (entries); beyond it (huge
// extents at fine voxels) blocks are found through the hash index.
constexpr size_t kMaxTable = size_t(1) << 22;

// The single-threaded walk of decay = raycast over the per-frame block
// table, with the same result as castRange() (below) bit for bit: the DDA
// of traverseRay() (the same setup, comparisons and additions, so the same
// voxels), two rays at a time in the two lanes of SSE2 registers (their
// steps are independent chains of additions: together they take about the
// time of one; four rays in two pairs measured slower), the voxel packed as
// one 64-bit integer relative to the table's corner (x | y << 21 | z << 42)
// from which the table index and the cell index are a few shifts and masks.
// A crossed cell not stamped with frame F gets one miss and the stamp;
// which ray gives it does not matter. What would depend on the order of the
// rays is the order in which blocks are created (and, over the memory
// budget, which ones): only the older of the two rays creates blocks; the
// younger one, on entering a block that does not exist, waits (the older
// one is finished alone first), so blocks are created in the order of the
// rays and of their steps, as by castRange(). Table entries: nullptr = not
// looked up yet, kOverBudget = the memory budget forbids the block.
constexpr uintptr_t kOverBudget = 1;
constexpr int kPackShift = 21;
constexpr uint64_t kField = (uint64_t(1) << kPackShift) - 1;
// Largest number of blocks per axis of the table for the packed walk.
constexpr size_t kMaxPackedBlocks = size_t(1) << (kPackShift - 3 - 1);

struct RayState
{
	uint64_t p = 0;        // packed voxel, relative to the table's corner
	int64_t step[3] = {};  // packed step per axis (0, +-1 in its field)
	double t[3] = {}, d[3] = {};  // tMax and tDelta per axis
	uint32_t n = 0;  // voxels left to visit, the current one included
};

template <class Cell, class Create, class Lookup>
struct TableWalk
{
	Cell** tab;
	size_t s0, s1;       // table strides of the x and y block indices
	int32_t ox, oy, oz;  // voxel of the table's corner
	uint32_t F;
	LogOddsFx miss, lmin, unknown;
	bool hasUnknown;
	Create& create;  // (x, y, z) -> cells of the block, nullptr over budget
	Lookup& lookup;  // (x, y, z) -> cells of an existing block or nullptr
	size_t over = 0;

	size_t blockIndex(uint64_t p) const
	{
		return size_t((p >> 3) & (kField >> 3)) * s0 +
		       size_t((p >> (kPackShift + 3)) & (kField >> 3)) * s1 +
		       size_t(p >> (2 * kPackShift + 3));
	}
	static size_t cellIndex(uint64_t p)
	{
		return size_t((p & 7) | ((p >> (kPackShift - 3)) & 0x38) |
		              ((p >> (2 * kPackShift - 6)) & 0x1c0));
	}
	Cell* blockOf(uint64_t p, bool mayCreate)
	{
		const int32_t x = int32_t(p & kField) + ox,
		              y = int32_t((p >> kPackShift) & kField) + oy,
		              z = int32_t(p >> (2 * kPackShift)) + oz;
		return mayCreate ? create(x, y, z) : lookup(x, y, z);
	}
	void missCell(Cell& c) const
	{
		if (c.stamp == F) return;  // hit, or missed by another ray
		if (c.stamp == 0 && hasUnknown) c.l = unknown;
		c.lPrev = c.l;
		c.l = std::max<LogOddsFx>(c.l - miss, lmin);
		c.stamp = F;
	}
	/** Visit by the oldest ray in flight: creates the block if needed. */
	void visitOld(uint64_t p)
	{
		const size_t bi = blockIndex(p);
		Cell* blk = tab[bi];
		if (uintptr_t(blk) <= kOverBudget)
		{
			if (!blk)
			{
				blk = blockOf(p, true);
				tab[bi] = blk ? blk : reinterpret_cast<Cell*>(kOverBudget);
			}
			if (uintptr_t(blk) <= kOverBudget)
			{
				++over;
				return;
			}
		}
		missCell(blk[cellIndex(p)]);
	}
	/** Visit by the younger ray: false (nothing done) if its block does
	 * not exist yet. */
	bool visitYoung(uint64_t p)
	{
		const size_t bi = blockIndex(p);
		Cell* blk = tab[bi];
		if (uintptr_t(blk) <= kOverBudget)
		{
			if (blk)
			{
				++over;
				return true;
			}
			blk = blockOf(p, false);
			if (!blk) return false;
			tab[bi] = blk;
		}
		missCell(blk[cellIndex(p)]);
		return true;
	}
	/** Walks the rest of ray \a s alone (as the oldest ray). */
	void finish(RayState& s)
	{
		for (; s.n; --s.n)
		{
			visitOld(s.p);
			const bool bx = (s.t[0] < s.t[1]) & (s.t[0] < s.t[2]);
			const bool by = !bx & (s.t[1] < s.t[2]);
			const bool bz = !bx & !by;
			s.p += uint64_t(bx ? s.step[0] : by ? s.step[1] : s.step[2]);
			s.t[0] += bx ? s.d[0] : 0.0;
			s.t[1] += by ? s.d[1] : 0.0;
			s.t[2] += bz ? s.d[2] : 0.0;
		}
	}
};

#if defined(BIMS_RAYCAST_SSE2)
/** Casts \a count rays from \a a (voxel units) to \a ends through the
 * table (see TableWalk). Returns the number of steps into blocks over the
 * memory budget. */
template <class Cell, class RayEnd, class Create, class Lookup>
size_t walkRaysTable(const double a[3], const RayEnd* ends, size_t count,
                     TableWalk<Cell, Create, Lookup>& w)
{
	const int32_t x0 = int32_t(std::floor(a[0])),
	              y0 = int32_t(std::floor(a[1])),
	              z0 = int32_t(std::floor(a[2]));
	const uint64_t p0 = uint64_t(x0 - w.ox) |
	                    (uint64_t(y0 - w.oy) << kPackShift) |
	                    (uint64_t(z0 - w.oz) << (2 * kPackShift));
	size_t r = 0;
	auto load = [&](RayState& s)
	{
		while (r < count)
		{
			const double* b = ends[r++].p;
			const int32_t ex = int32_t(std::floor(b[0])),
			              ey = int32_t(std::floor(b[1])),
			              ez = int32_t(std::floor(b[2]));
			s.n = uint32_t(std::abs(ex - x0) + std::abs(ey - y0) +
			               std::abs(ez - z0));
			if (s.n == 0) continue;
			int32_t sx, sy, sz;
			ddaAxisSetup(a[0], b[0], x0, sx, s.t[0], s.d[0]);
			ddaAxisSetup(a[1], b[1], y0, sy, s.t[1], s.d[1]);
			ddaAxisSetup(a[2], b[2], z0, sz, s.t[2], s.d[2]);
			s.step[0] = sx;
			s.step[1] = int64_t(sy) * (int64_t(1) << kPackShift);
			s.step[2] = int64_t(sz) * (int64_t(1) << (2 * kPackShift));
			s.p = p0;
			return true;
		}
		return false;
	};
	RayState A, B;  // A: the older ray
	bool hasA = load(A), hasB = hasA && load(B);
	const __m128d ones = _mm_castsi128_pd(_mm_set1_epi32(-1));
	while (hasB)
	{
		__m128d T0 = _mm_set_pd(B.t[0], A.t[0]),
		        T1 = _mm_set_pd(B.t[1], A.t[1]),
		        T2 = _mm_set_pd(B.t[2], A.t[2]);
		const __m128d D0 = _mm_set_pd(B.d[0], A.d[0]),
		              D1 = _mm_set_pd(B.d[1], A.d[1]),
		              D2 = _mm_set_pd(B.d[2], A.d[2]);
		const __m128i S0 = _mm_set_epi64x(B.step[0], A.step[0]),
		              S1 = _mm_set_epi64x(B.step[1], A.step[1]),
		              S2 = _mm_set_epi64x(B.step[2], A.step[2]);
		__m128i P = _mm_set_epi64x(int64_t(B.p), int64_t(A.p));
		const uint32_t k = std::min(A.n, B.n);
		uint32_t done = 0;
		bool parked = false;
		for (; done < k; ++done)
		{
			const uint64_t pa = uint64_t(_mm_cvtsi128_si64(P)),
			               pb = uint64_t(
			                   _mm_cvtsi128_si64(_mm_unpackhi_epi64(P, P)));
			if (!w.visitYoung(pb))
			{
				parked = true;
				break;
			}
			w.visitOld(pa);
			// The step of traverseRay() in both lanes.
			const __m128d lxy = _mm_cmplt_pd(T0, T1),
			              lxz = _mm_cmplt_pd(T0, T2),
			              lyz = _mm_cmplt_pd(T1, T2);
			const __m128d mx = _mm_and_pd(lxy, lxz);
			const __m128d my = _mm_andnot_pd(mx, lyz);
			const __m128d mz = _mm_andnot_pd(_mm_or_pd(mx, my), ones);
			T0 = _mm_add_pd(T0, _mm_and_pd(mx, D0));
			T1 = _mm_add_pd(T1, _mm_and_pd(my, D1));
			T2 = _mm_add_pd(T2, _mm_and_pd(mz, D2));
			const __m128i inc = _mm_or_si128(
			    _mm_or_si128(_mm_and_si128(_mm_castpd_si128(mx), S0),
			                 _mm_and_si128(_mm_castpd_si128(my), S1)),
			    _mm_and_si128(_mm_castpd_si128(mz), S2));
			P = _mm_add_epi64(P, inc);
		}
		// Back to the scalar states.
		auto lo = [](__m128d v) { return _mm_cvtsd_f64(v); };
		auto hi = [](__m128d v)
		{ return _mm_cvtsd_f64(_mm_unpackhi_pd(v, v)); };
		A.t[0] = lo(T0), A.t[1] = lo(T1), A.t[2] = lo(T2);
		B.t[0] = hi(T0), B.t[1] = hi(T1), B.t[2] = hi(T2);
		A.p = uint64_t(_mm_cvtsi128_si64(P));
		B.p = uint64_t(_mm_cvtsi128_si64(_mm_unpackhi_epi64(P, P)));
		A.n -= done;
		B.n -= done;
		if (parked)
		{
			w.finish(A);  // B waits for the blocks A creates
			A = B;
			hasB = load(B);
		}
		else if (A.n == 0)
		{
			A = B;
			hasB = load(B);
		}
		else if (B.n == 0)
			hasB = load(B);
	}
	if (hasA) w.finish(A);
	return w.over;
}
#endif

}  // namespace

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

	// The rays' end points in voxel units, in tile order.
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
	}
	else
	{
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
		}
		else
		{
			// Counting sort of the readings by tile.
			const int tw = (W + kTile - 1) / kTile,
			          th = (H + kTile - 1) / kTile;
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
	}
	if (ends.empty()) return;

	// Bounding box of the rays in blocks (one block of margin: a DDA may
	// round one voxel past its end on an axis).
	int32_t lo[3], hi[3];
	for (int k = 0; k < 3; ++k) lo[k] = hi[k] = int32_t(std::floor(a[k]));
	for (const auto& e : ends)
		for (int k = 0; k < 3; ++k)
		{
			const int32_t v = int32_t(std::floor(e.p[k]));
			lo[k] = std::min(lo[k], v);
			hi[k] = std::max(hi[k], v);
		}
	size_t n[3], cells = 1;
	for (int k = 0; k < 3; ++k)
	{
		lo[k] = (lo[k] >> 3) - 1;
		hi[k] = (hi[k] >> 3) + 1;
		n[k] = size_t(hi[k] - lo[k] + 1);
		cells *= n[k];
	}

	size_t over = 0;
	const LogOddsFx miss = miss_, lmin = lmin_;
	auto missCell = [&](Cell& c) { applyMiss(c, F); };
	auto cast = [&](const RayEnd& e, auto&& visit)
	{ traverseRay(a, e.p, visit); };
	if (cells > kMaxTable)
	{
		Storage::Accessor acc(grid_);
		for (const auto& e : ends)
			cast(e,
			     [&](int32_t x, int32_t y, int32_t z)
			     {
				     Cell* c = acc.get(x, y, z);
				     if (c)
					     missCell(*c);
				     else
					     ++over;
			     });
	}
	else
	{
		// A per-frame table of the blocks in the rays' bounding box: one
		// array read per voxel instead of a hash lookup per block entered.
		auto& tab = blockTable_;
		tab.assign(cells, nullptr);
		static Cell overBudget;  // marks blocks the budget forbids
		Cell* const kOver = &overBudget;
		std::mutex creating;  // with threads: the hash index, tab writes
		auto create = [&](int32_t x, int32_t y, int32_t z)
		{
			const uint32_t b =
			    grid_.findOrCreateBlock(packKey(x >> 3, y >> 3, z >> 3));
			return b == FlatHashMap::kNotFound ? kOver : grid_.block(b).cells;
		};
		// Casts rays [r0, r1). Shared: other threads cast at the same time;
		// a cell's miss is then claimed by a compare-and-swap of its stamp
		// (hits were stamped before), so that it is applied once.
		auto castRange = [&](auto sharedTag, size_t r0, size_t r1, size_t& ov)
		{
			constexpr bool kShared = decltype(sharedTag)::value;
			for (size_t r = r0; r < r1; ++r)
				cast(ends[r],
				     [&](int32_t x, int32_t y, int32_t z)
				     {
					     const size_t bi = (size_t((x >> 3) - lo[0]) * n[1] +
					                        size_t((y >> 3) - lo[1])) *
					                           n[2] +
					                       size_t((z >> 3) - lo[2]);
					     Cell* blk;
					     if constexpr (kShared)
					     {
						     blk = __atomic_load_n(&tab[bi], __ATOMIC_ACQUIRE);
						     if (!blk)
						     {
							     std::lock_guard<std::mutex> lock(creating);
							     blk = tab[bi];
							     if (!blk)
								     __atomic_store_n(&tab[bi],
								                      blk = create(x, y, z),
								                      __ATOMIC_RELEASE);
						     }
					     }
					     else
					     {
						     blk = tab[bi];
						     if (!blk) blk = tab[bi] = create(x, y, z);
					     }
					     if (blk == kOver)
					     {
						     ++ov;
						     return;
					     }
					     Cell& c = blk[Storage::cellIndexOf(x, y, z)];
					     if constexpr (kShared)
					     {
						     uint32_t s =
						         __atomic_load_n(&c.stamp, __ATOMIC_RELAXED);
						     if (s == F ||
						         !__atomic_compare_exchange_n(
						             &c.stamp, &s, F, false, __ATOMIC_RELAXED,
						             __ATOMIC_RELAXED))
							     return;  // hit, or missed by another ray
						     startIfUnobserved(
						         c, s);  // s: the stamp before the claim
						     c.lPrev = c.l;
						     c.l = std::max<LogOddsFx>(c.l - miss, lmin);
					     }
					     else
						     missCell(c);
				     });
		};
		constexpr size_t kChunk = 2048;  // rays per work item (32 tiles)
		const size_t threads =
		    std::min<size_t>(size_t(params_.raycast_threads),
		                     (ends.size() + kChunk - 1) / kChunk);
		bool packed = true;
		for (int k = 0; k < 3; ++k) packed = packed && n[k] <= kMaxPackedBlocks;
#if !defined(BIMS_RAYCAST_SSE2)
		packed = false;
#endif
		if (threads <= 1 && !packed)
			castRange(std::false_type(), 0, ends.size(), over);
		else if (threads <= 1)
		{
#if defined(BIMS_RAYCAST_SSE2)
			auto createBlock = [&](int32_t x, int32_t y, int32_t z) -> Cell*
			{
				const uint32_t b =
				    grid_.findOrCreateBlock(packKey(x >> 3, y >> 3, z >> 3));
				return b == FlatHashMap::kNotFound ? nullptr
				                                   : grid_.block(b).cells;
			};
			auto lookupBlock = [&](int32_t x, int32_t y, int32_t z) -> Cell*
			{
				auto* b = grid_.findBlock(packKey(x >> 3, y >> 3, z >> 3));
				return b ? b->cells : nullptr;
			};
			TableWalk<Cell, decltype(createBlock), decltype(lookupBlock)> w{
			    tab.data(),  n[1] * n[2], n[2],       lo[0] * 8, lo[1] * 8,
			    lo[2] * 8,   F,           miss,       lmin,      unknown_,
			    hasUnknown_, createBlock, lookupBlock};
			over += walkRaysTable(a, ends.data(), ends.size(), w);
#endif
		}
		else
		{
			std::atomic<size_t> next{0};
			std::vector<size_t> overs(threads, 0);
			auto worker = [&](size_t t)
			{
				for (;;)
				{
					const size_t r0 = next.fetch_add(kChunk);
					if (r0 >= ends.size()) break;
					castRange(std::true_type(), r0,
					          std::min(ends.size(), r0 + kChunk), overs[t]);
				}
			};
			std::vector<std::thread> pool;
			for (size_t t = 1; t < threads; ++t) pool.emplace_back(worker, t);
			worker(0);
			for (auto& th : pool) th.join();
			for (size_t v : overs) over += v;
		}
	}
	if (over)
	{
		FrameStats st;
		st.overBudget = over;
		accountFrame(st);
	}
}

// decay = frustum. The per-cell rule (a cell decays iff its centre is in
// front of the camera, projects into the image, onto a measured depth d,
// and lies wholly in front of it: z + half diagonal < d) is applied to
// every stored cell of the blocks near the view, but whole boxes of cells
// are decided at once where the rule provably gives one answer for all of
// them: the camera coordinates of a cell are affine in its indices, so the
// centres of a box lie between those of its corners, and its pixels in the
// rectangle spanned by the corners' projections; the depths of that
// rectangle are bounded by per-tile minima and maxima of the depth image.
// Boxes with no decaying cell are skipped, boxes where every cell decays
// are decayed without projection, the others are split into octants (down
// to 4^3 cells) or decided cell by cell. The camera coordinates are formed
// from per-axis products, the same floating-point operations as for one
// cell alone, so the decisions are those of the plain rule, bit for bit.
void COccupancyBayesGrid::decayFrustum(const FrameCloud& f, uint32_t F)
{
	const auto& K = f.K;
	if (K.width <= 0 || f.depth.empty()) return;  // no frustum known
	const double s = params_.voxel_size;
	const auto& R = f.T_WC.getRotationMatrix();  // R_WC
	const mrpt::math::TPoint3D t = f.T_WC.translation();
	// Side planes of the frustum in {C} (through the origin), normalised.
	double planes[4][3] = {{1, 0, (K.cx + 0.5) / K.fx},
	                       {-1, 0, (K.width - 0.5 - K.cx) / K.fx},
	                       {0, 1, (K.cy + 0.5) / K.fy},
	                       {0, -1, (K.height - 0.5 - K.cy) / K.fy}};
	for (auto& pl : planes)
	{
		const double n =
		    std::sqrt(pl[0] * pl[0] + pl[1] * pl[1] + pl[2] * pl[2]);
		for (auto& v : pl) v /= n;
	}
	const int D = Storage::kDim;
	const double blockRadius = D * s * std::sqrt(3.0) / 2;
	const double cellHalfDiag = s * std::sqrt(3.0) / 2;
	const double maxR = params_.max_range;
	auto toCam = [&](double x, double y, double z, double c[3])
	{
		const double dx = x - t.x, dy = y - t.y, dz = z - t.z;
		for (int r = 0; r < 3; ++r)
			c[r] = R(0, r) * dx + R(1, r) * dy + R(2, r) * dz;  // R^T d
	};

	// Per tile of kTilePx^2 pixels: largest depth, smallest non-zero depth
	// (+inf if none) and whether a pixel has no depth.
	constexpr int kTilePx = 8;
	const int W = K.width, H = K.height;
	const int tw = (W + kTilePx - 1) / kTilePx,
	          th = (H + kTilePx - 1) / kTilePx;
	tileMax_.assign(size_t(tw) * th, 0.f);
	tileMinPos_.assign(size_t(tw) * th, INFINITY);
	tileZero_.assign(size_t(tw) * th, 0);
	for (int v = 0; v < H; ++v)
	{
		const float* row = f.depth.data() + size_t(v) * W;
		const size_t t0 = size_t(v / kTilePx) * tw;
		for (int u = 0; u < W; ++u)
		{
			const float d = row[u];
			const size_t ti = t0 + size_t(u / kTilePx);
			tileMax_[ti] = std::max(tileMax_[ti], d);
			if (d > 0)
				tileMinPos_[ti] = std::min(tileMinPos_[ti], d);
			else
				tileZero_[ti] = 1;
		}
	}

	// Margins of the box decisions: far larger than the rounding of the
	// coordinates (~1e-14 m) and of the projections (~1e-12 px).
	constexpr double kZMargin = 1e-7;
	enum Verdict
	{
		None,
		All,
		Mixed
	};
	for (size_t b = 0; b < grid_.numBlocks(); ++b)
	{
		const VoxelKey o = grid_.blockOrigin(b);
		double pc[3];
		toCam((o.x + D / 2.0) * s, (o.y + D / 2.0) * s, (o.z + D / 2.0) * s,
		      pc);
		if (pc[2] < -blockRadius || pc[2] > maxR + blockRadius) continue;
		bool outside = false;
		for (const auto& pl : planes)
			if (pl[0] * pc[0] + pl[1] * pc[1] + pl[2] * pc[2] < -blockRadius)
				outside = true;
		if (outside) continue;
		auto& blk = grid_.block(b);
		// The terms of R^T (centre - t) per axis and index: cell (i, j, k)
		// has c[r] = (ax[r][i] + ay[r][j]) + az[r][k], as toCam() forms it.
		double ax[3][D], ay[3][D], az[3][D];
		for (int i = 0; i < D; ++i)
		{
			const double dx = (o.x + i + 0.5) * s - t.x;
			const double dy = (o.y + i + 0.5) * s - t.y;
			const double dz = (o.z + i + 0.5) * s - t.z;
			for (int r = 0; r < 3; ++r)
			{
				ax[r][i] = R(0, r) * dx;
				ay[r][i] = R(1, r) * dy;
				az[r][i] = R(2, r) * dz;
			}
		}
		auto cam = [&](int i, int j, int k, int r)
		{ return ax[r][i] + ay[r][j] + az[r][k]; };
		auto cellRule = [&](int i, int j, int k)
		{
			Cell& cell =
			    blk.cells[size_t(i) | (size_t(j) << 3) | (size_t(k) << 6)];
			if (cell.stamp == F) return;
			const double z = cam(i, j, k, 2);
			if (z <= 1e-6) return;
			const double u = K.fx * cam(i, j, k, 0) / z + K.cx;
			const double v = K.fy * cam(i, j, k, 1) / z + K.cy;
			const long ui = std::lround(u), vi = std::lround(v);
			if (ui < 0 || vi < 0 || ui >= W || vi >= H) return;
			const float d = f.depth[size_t(vi) * W + size_t(ui)];
			// Decay only cells wholly in front of the measured depth.
			if (d > 0 && z + cellHalfDiag < d) applyMiss(cell, F);
		};
		// The verdict for the box [i0, i0+n) x [j0, j0+n) x [k0, k0+n).
		auto verdict = [&](int i0, int j0, int k0, int n)
		{
			const int e = n - 1;
			double zlo = INFINITY, zhi = -INFINITY;
			double ulo = INFINITY, uhi = -INFINITY, vlo = INFINITY,
			       vhi = -INFINITY;
			for (int q = 0; q < 8; ++q)
			{
				const int i = i0 + ((q & 1) ? e : 0),
				          j = j0 + ((q & 2) ? e : 0),
				          k = k0 + ((q & 4) ? e : 0);
				const double z = cam(i, j, k, 2);
				zlo = std::min(zlo, z);
				zhi = std::max(zhi, z);
				if (z <= 1e-6 + kZMargin) return Mixed;
				const double u = K.fx * cam(i, j, k, 0) / z + K.cx;
				const double v = K.fy * cam(i, j, k, 1) / z + K.cy;
				ulo = std::min(ulo, u);
				uhi = std::max(uhi, u);
				vlo = std::min(vlo, v);
				vhi = std::max(vhi, v);
			}
			// Every centre projects into [ulo, uhi] x [vlo, vhi]; its pixel
			// (rounded) into this rectangle of pixels.
			const double u0 = std::floor(ulo) - 1, u1 = std::ceil(uhi) + 1,
			             v0 = std::floor(vlo) - 1, v1 = std::ceil(vhi) + 1;
			if (u1 < 0 || v1 < 0 || u0 >= W || v0 >= H) return None;
			const bool inside = u0 >= 0 && v0 >= 0 && u1 < W && v1 < H;
			const int pu0 = int(std::max(u0, 0.0)),
			          pu1 = int(std::min(u1, double(W - 1))),
			          pv0 = int(std::max(v0, 0.0)),
			          pv1 = int(std::min(v1, double(H - 1)));
			float dMax = 0, dMinPos = INFINITY;
			bool zero = false;
			for (int ty = pv0 / kTilePx; ty <= pv1 / kTilePx; ++ty)
				for (int tx = pu0 / kTilePx; tx <= pu1 / kTilePx; ++tx)
				{
					const size_t ti = size_t(ty) * tw + size_t(tx);
					dMax = std::max(dMax, tileMax_[ti]);
					dMinPos = std::min(dMinPos, tileMinPos_[ti]);
					zero = zero || tileZero_[ti];
				}
			// No cell is in front of any depth of its rectangle.
			if (double(dMax) <= zlo + cellHalfDiag - kZMargin) return None;
			// Every cell is in the image and in front of every depth there.
			if (inside && !zero &&
			    double(dMinPos) > zhi + cellHalfDiag + kZMargin)
				return All;
			return Mixed;
		};
		auto decide = [&](auto&& self, int i0, int j0, int k0, int n) -> void
		{
			const Verdict vd = verdict(i0, j0, k0, n);
			if (vd == None) return;
			if (vd == All)
			{
				for (int k = k0; k < k0 + n; ++k)
					for (int j = j0; j < j0 + n; ++j)
						for (int i = i0; i < i0 + n; ++i)
							applyMiss(blk.cells[size_t(i) | (size_t(j) << 3) |
							                    (size_t(k) << 6)],
							          F);
				return;
			}
			if (n > 4)
			{
				const int h = n / 2;
				for (int q = 0; q < 8; ++q)
					self(self, i0 + ((q & 1) ? h : 0), j0 + ((q & 2) ? h : 0),
					     k0 + ((q & 4) ? h : 0), h);
				return;
			}
			for (int k = k0; k < k0 + n; ++k)
				for (int j = j0; j < j0 + n; ++j)
					for (int i = i0; i < i0 + n; ++i) cellRule(i, j, k);
		};
		decide(decide, 0, 0, 0, D);
	}
}

}  // namespace bims::maps
