// decay = raycast, the walk (ray_marks.h).
#include <bims/maps/ray_marks.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

// The two-lane walk needs SSE2 and 64-bit integer moves (x86-64).
#if defined(__SSE2__) && defined(__x86_64__)
#define BIMS_RAYMARKS_SSE2 1
#include <emmintrin.h>
#endif

namespace bims::maps
{
RayBox::RayBox(const int32_t l[3], const int32_t h[3])
{
	for (int k = 0; k < 3; ++k)
	{
		lo[k] = l[k];
		n[k] = size_t(h[k] - l[k] + 1);
	}
	rowWords = (n[0] * 8 + 63) / 64;
}

void RayMarks::reset(const RayBox& box)
{
	bits.resize(2 * box.words());
	for (size_t w = 0; w < bits.size(); w += 2)
	{
		bits[w] = 0;
		bits[w + 1] = ~uint64_t(0);
	}
	state.assign(box.blocks(), kUnknown);
	firstVisit.assign(box.blocks(), kNoVisit);
}

namespace
{
/** The slow part of a visit: the first visit of a voxel whose block this
 * thread has not looked up, or a visit of a block that is not stored. A
 * block no longer needs slow visits once it is stored, or once it is
 * missing and visited by the oldest ray in flight: every later visit by
 * this thread is then of that ray's later steps or of younger rays, with
 * later (ray, step). */
struct Resolver
{
	const RayBox& box;
	BlockStored stored;
	const void* ctx;
	RayMarks& m;

	void visit(uint64_t g, uint32_t ray, uint32_t step, uint32_t oldest)
	{
		const uint64_t row = g / box.rowBits(), ny = box.n[1] * 8;
		const size_t x = size_t(g % box.rowBits()), y = size_t(row % ny),
		             z = size_t(row / ny);
		const size_t bx = x >> 3, by = y >> 3, bz = z >> 3;
		const size_t bi = box.blockIndex(bx, by, bz);
		uint8_t& st = m.state[bi];
		if (st == RayMarks::kUnknown)
		{
			st = stored(ctx, box.lo[0] + int32_t(bx), box.lo[1] + int32_t(by),
			            box.lo[2] + int32_t(bz))
			         ? RayMarks::kStored
			         : RayMarks::kMissing;
			if (st == RayMarks::kStored) clearUnresolved(bx, by, bz);
		}
		if (st == RayMarks::kMissing)
		{
			m.firstVisit[bi] =
			    std::min(m.firstVisit[bi], (uint64_t(ray) << 32) | step);
			if (ray == oldest) clearUnresolved(bx, by, bz);
		}
	}
	/** The block's voxels need no more slow visits. */
	void clearUnresolved(size_t bx, size_t by, size_t bz)
	{
		const uint64_t byteMask = ~(uint64_t(0xff) << ((bx & 7) * 8));
		const size_t ny = box.n[1] * 8;
		for (size_t z = bz * 8; z < bz * 8 + 8; ++z)
			for (size_t y = by * 8; y < by * 8 + 8; ++y)
			{
				const size_t w = (z * ny + y) * box.rowWords + (bx >> 3);
				m.bits[2 * w + 1] &= byteMask;
			}
	}
};

/** Marks voxel bit \a g, visited by \a ray at its \a step (\a oldest: the
 * oldest ray this thread walks at the time). */
inline void mark(uint64_t g, uint32_t ray, uint32_t step, uint32_t oldest,
                 uint64_t* bits, Resolver& res)
{
	const uint64_t bit = uint64_t(1) << (g & 63);
	uint64_t* q = bits + 2 * (g >> 6);
	if (q[1] & bit) res.visit(g, ray, step, oldest);
	q[0] |= bit;
}

#if defined(BIMS_RAYMARKS_SSE2)
/** One ray of the two-lane walk: the state of traverseRay() with the voxel
 * as its bit index. */
struct Lane
{
	uint64_t g = 0;
	int64_t inc[3] = {};          // bit increment of a step per axis
	double t[3] = {}, d[3] = {};  // tMax and tDelta per axis
	uint32_t n = 0;               // voxels left, the current one included
	uint32_t step = 0;            // voxels visited so far
	uint32_t ray = 0;
};

/** The rays two at a time in the lanes of SSE2 registers: the setup of
 * traverseRay() (ddaAxisSetup), then its comparisons and additions of tMax
 * in both lanes, so the same voxels. A lone last ray runs in both lanes. */
void markRaysSse2(const double a[3], const RayEnd* ends, size_t r0, size_t r1,
                  const RayBox& box, Resolver& res)
{
	const int32_t x0 = int32_t(std::floor(a[0])),
	              y0 = int32_t(std::floor(a[1])),
	              z0 = int32_t(std::floor(a[2]));
	const uint64_t g0 = box.bitOf(x0, y0, z0);
	const int64_t rowBits = int64_t(box.rowBits()),
	              planeBits = int64_t(box.planeBits());
	uint64_t* bits = res.m.bits.data();
	size_t r = r0;
	auto load = [&](Lane& s)
	{
		while (r < r1)
		{
			const size_t ri = r++;
			const double* b = ends[ri].p;
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
			s.inc[0] = sx;
			s.inc[1] = sy * rowBits;
			s.inc[2] = sz * planeBits;
			s.g = g0;
			s.step = 0;
			s.ray = uint32_t(ri);
			return true;
		}
		return false;
	};
	Lane A, B;
	if (!load(A)) return;
	if (!load(B)) B = A;
	const __m128d ones = _mm_castsi128_pd(_mm_set1_epi32(-1));
	for (;;)
	{
		__m128d T0 = _mm_set_pd(B.t[0], A.t[0]),
		        T1 = _mm_set_pd(B.t[1], A.t[1]),
		        T2 = _mm_set_pd(B.t[2], A.t[2]);
		const __m128d D0 = _mm_set_pd(B.d[0], A.d[0]),
		              D1 = _mm_set_pd(B.d[1], A.d[1]),
		              D2 = _mm_set_pd(B.d[2], A.d[2]);
		const __m128i S0 = _mm_set_epi64x(B.inc[0], A.inc[0]),
		              S1 = _mm_set_epi64x(B.inc[1], A.inc[1]),
		              S2 = _mm_set_epi64x(B.inc[2], A.inc[2]);
		__m128i G = _mm_set_epi64x(int64_t(B.g), int64_t(A.g));
		const uint32_t k = std::min(A.n, B.n), oldest = std::min(A.ray, B.ray);
		for (uint32_t i = 0; i < k; ++i)
		{
			mark(uint64_t(_mm_cvtsi128_si64(G)), A.ray, A.step + i, oldest,
			     bits, res);
			mark(uint64_t(_mm_cvtsi128_si64(_mm_unpackhi_epi64(G, G))), B.ray,
			     B.step + i, oldest, bits, res);
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
			G = _mm_add_epi64(G, inc);
		}
		// Back to the scalar states.
		auto lo = [](__m128d v) { return _mm_cvtsd_f64(v); };
		auto hi = [](__m128d v)
		{ return _mm_cvtsd_f64(_mm_unpackhi_pd(v, v)); };
		A.t[0] = lo(T0), A.t[1] = lo(T1), A.t[2] = lo(T2);
		B.t[0] = hi(T0), B.t[1] = hi(T1), B.t[2] = hi(T2);
		A.g = uint64_t(_mm_cvtsi128_si64(G));
		B.g = uint64_t(_mm_cvtsi128_si64(_mm_unpackhi_epi64(G, G)));
		A.n -= k, B.n -= k;
		A.step += k, B.step += k;
		const bool same = A.ray == B.ray;
		if (A.n == 0 && !load(A))
		{
			if (B.n == 0 || same) return;
			A = B;
		}
		if (B.n == 0 && !load(B))
		{
			if (A.n == 0) return;
			B = A;
		}
	}
}
#endif

}  // namespace

void markRays(const double a[3], const RayEnd* ends, size_t r0, size_t r1,
              const RayBox& box, BlockStored stored, const void* ctx,
              RayMarks& m)
{
	Resolver res{box, stored, ctx, m};
#if defined(BIMS_RAYMARKS_SSE2)
	markRaysSse2(a, ends, r0, r1, box, res);
#else
	for (size_t r = r0; r < r1; ++r)
	{
		uint32_t step = 0;
		traverseRay(a, ends[r].p,
		            [&](int32_t x, int32_t y, int32_t z)
		            {
			            mark(box.bitOf(x, y, z), uint32_t(r), step++,
			                 uint32_t(r), m.bits.data(), res);
		            });
	}
#endif
}

void mergeRayMarks(RayMarks& m, const RayMarks& o)
{
	for (size_t w = 0; w < m.bits.size(); w += 2) m.bits[w] |= o.bits[w];
	for (size_t b = 0; b < m.state.size(); ++b)
	{
		if (m.state[b] == RayMarks::kUnknown) m.state[b] = o.state[b];
		m.firstVisit[b] = std::min(m.firstVisit[b], o.firstVisit[b]);
	}
}

}  // namespace bims::maps
