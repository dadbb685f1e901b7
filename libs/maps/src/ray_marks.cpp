// decay = raycast, the walk (ray_marks.h).
#include <bims/maps/ray_marks.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

namespace bims::maps
{
namespace
{
/** The bits of \a v placed, lowest first, at the set bits of \a m. */
uint64_t deposit(uint64_t v, uint64_t m)
{
	uint64_t r = 0;
	for (unsigned b = 0; m; m &= m - 1, ++b)
		if ((v >> b) & 1) r |= m & (~m + 1);
	return r;
}
/** The bits of \a g at the set bits of \a m, packed lowest first. */
uint64_t extract(uint64_t g, uint64_t m)
{
	uint64_t r = 0;
	for (unsigned b = 0; m; m &= m - 1, ++b)
		if (g & m & (~m + 1)) r |= uint64_t(1) << b;
	return r;
}
unsigned ceilLog2(size_t n)
{
	unsigned k = 0;
	while ((size_t(1) << k) < n) ++k;
	return k;
}
}  // namespace

RayBox::RayBox(const int32_t l[3], const int32_t h[3])
{
	unsigned most = 0;
	for (int k = 0; k < 3; ++k)
	{
		lo[k] = l[k];
		logN[k] = ceilLog2(size_t(h[k] - l[k] + 1));
		most = std::max(most, logN[k]);
		mask[k] = uint64_t(7) << (3 * k);  // the cell in the block
	}
	unsigned pos = 9;  // then the block's bits, interleaved x, y, z
	for (unsigned b = 0; b < most; ++b)
		for (int k = 0; k < 3; ++k)
			if (b < logN[k]) mask[k] |= uint64_t(1) << pos++;
}

RayBox RayBox::around(const double a[3], const RayEnd* ends, size_t n)
{
	int32_t lo[3], hi[3];
	for (int k = 0; k < 3; ++k) lo[k] = hi[k] = int32_t(std::floor(a[k]));
	for (size_t i = 0; i < n; ++i)
		for (int k = 0; k < 3; ++k)
		{
			const int32_t v = int32_t(std::floor(ends[i].p[k]));
			lo[k] = std::min(lo[k], v);
			hi[k] = std::max(hi[k], v);
		}
	for (int k = 0; k < 3; ++k)
	{
		lo[k] = (lo[k] >> 3) - 1;
		hi[k] = (hi[k] >> 3) + 1;
	}
	return RayBox(lo, hi);
}

uint64_t RayBox::bitOf(int32_t x, int32_t y, int32_t z) const
{
	return deposit(uint64_t(x - lo[0] * 8), mask[0]) |
	       deposit(uint64_t(y - lo[1] * 8), mask[1]) |
	       deposit(uint64_t(z - lo[2] * 8), mask[2]);
}

void RayBox::blockCoords(size_t b, int32_t out[3]) const
{
	for (int k = 0; k < 3; ++k)
		out[k] = lo[k] + int32_t(extract(uint64_t(b) << 9, mask[k]) >> 3);
}

void RayMarks::reset(const RayBox& box)
{
	// Invariant between frames: only the touched blocks have bits set.
	for (const uint32_t b : touched)
		std::memset(&bits[8 * size_t(b)], 0, 8 * sizeof(uint64_t));
	touched.clear();
	if (bits.size() < box.words()) bits.resize(box.words(), 0);
	state.assign(box.blocks(), kUnknown);
	if (firstVisit.size() < box.blocks()) firstVisit.resize(box.blocks());
}

namespace
{
/** Runs of a ray's visits inside one word of the bitset (one row z of cells
 * of one block), collected by a walker and applied in batches: the word,
 * its bits, and the run's first visit (ray << 32 | step). A block's
 * earliest visit is the start of one of its runs. */
struct Runs
{
	static constexpr size_t kCap = 1024;
	static constexpr size_t kSlack = 16;  // a walker may write 16 past n
	alignas(64) int64_t word[kCap + kSlack];
	alignas(64) int64_t bits[kCap + kSlack];
	alignas(64) int64_t first[kCap + kSlack];
	size_t n = 0;
};

/** What a walker needs: the rays, the box, the marks. */
struct Walk
{
	const double* a;
	const RayEnd* ends;
	size_t r0, r1;
	const RayBox& box;
	BlockStored stored;
	const void* ctx;
	RayMarks& m;
	Runs& runs;

	/** Applies the runs collected: each word's bits set; each block entered
	 * for the first time looked up; the earliest first visit kept for the
	 * blocks not stored. */
	void apply()
	{
		// Locals: the stores to the bits could alias the members.
		uint64_t* out = m.bits.data();
		const uint8_t* state = m.state.data();
		uint64_t* firstVisit = m.firstVisit.data();
		const int64_t *word = runs.word, *bits = runs.bits, *first = runs.first;
		const size_t n = runs.n;
		for (size_t i = 0; i < n; ++i)
		{
			const uint64_t w = uint64_t(word[i]), v = uint64_t(first[i]);
			const size_t b = size_t(w >> 3);
			if (state[b] != RayMarks::kStored)
			{
				if (state[b] == RayMarks::kUnknown)
					lookUp(b, v);
				else
					firstVisit[b] = std::min(firstVisit[b], v);
			}
			out[w] |= uint64_t(bits[i]);
		}
		runs.n = 0;
	}
	/** Block \a b, entered for the first time by this thread at \a v. */
	[[gnu::noinline]] void lookUp(size_t b, uint64_t v)
	{
		int32_t c[3];
		box.blockCoords(b, c);
		m.touched.push_back(uint32_t(b));
		m.state[b] = stored(ctx, c[0], c[1], c[2]) ? RayMarks::kStored
		                                           : RayMarks::kMissing;
		m.firstVisit[b] = v;
	}
	/** One run; applies the batch when it is full. */
	void push(uint64_t word, uint64_t bits, uint64_t first)
	{
		runs.word[runs.n] = int64_t(word);
		runs.bits[runs.n] = int64_t(bits);
		runs.first[runs.n] = int64_t(first);
		if (++runs.n == Runs::kCap) apply();
	}
};

/** The walker's operations on one lane in scalars (CPUs without AVX2,
 * other architectures); the vector sets below have the same members. */
struct ScalarOps
{
	static constexpr int N = 1;
	using D = double;
	using I = int64_t;
	using M = bool;
	static D loadD(const double* p) { return *p; }
	static I loadI(const int64_t* p) { return *p; }
	static void storeD(double* p, D v) { *p = v; }
	static void storeI(int64_t* p, I v) { *p = v; }
	static I set1(int64_t v) { return v; }
	static I add(I a, I b) { return int64_t(uint64_t(a) + uint64_t(b)); }
	/** The word of a bit index, and its bit in the word. */
	static I word(I g) { return int64_t(uint64_t(g) >> 6); }
	static I bit(I g) { return int64_t(uint64_t(1) << (g & 63)); }
	static M differ(I a, I b) { return a != b; }
	/** m ? a : b */
	static I select(M m, I a, I b) { return m ? a : b; }
	static I orI(I a, I b) { return a | b; }
	/** The lanes of \a v in \a m, packed at \a out (N written); how many. */
	static size_t compress(M m, I v, int64_t* out)
	{
		*out = v;
		return m;
	}
	static M lt(D a, D b) { return a < b; }
	static M le(D a, D b) { return a <= b; }
	static M both(M a, M b) { return a && b; }
	/** m ? t + d : t */
	static D addIf(D t, M m, D d) { return m ? t + d : t; }
	/** mx ? a : my ? b : c */
	static I pick(M mx, M my, I a, I b, I c) { return mx ? a : my ? b : c; }
	/** RayBox::step() */
	static I stepBits(I g, I m, I c)
	{
		return int64_t(RayBox::step(uint64_t(g), uint64_t(m), uint64_t(c)));
	}
};
#define BIMS_WALK_NAME walk1
#define BIMS_WALK_OPS ScalarOps
#define BIMS_WALK_TARGET
#include "ray_walk_lanes.inc"

#if defined(__x86_64__) && defined(__GNUC__)
#define BIMS_RAY_LANES_X86 1
// The vector operations of the walker (ray_walk_lanes.inc) per instruction
// set: N lanes of doubles (D) and 64-bit integers (I), lane masks (M).
#define BIMS_AVX2 __attribute__((target("avx2")))
struct Avx2Ops
{
	static constexpr int N = 4;
	using D = __m256d;
	using I = __m256i;
	using M = __m256i;
	BIMS_AVX2 static D loadD(const double* p) { return _mm256_load_pd(p); }
	BIMS_AVX2 static I loadI(const int64_t* p)
	{
		return _mm256_load_si256(reinterpret_cast<const __m256i*>(p));
	}
	BIMS_AVX2 static void storeD(double* p, D v) { _mm256_store_pd(p, v); }
	BIMS_AVX2 static void storeI(int64_t* p, I v)
	{
		_mm256_store_si256(reinterpret_cast<__m256i*>(p), v);
	}
	BIMS_AVX2 static I set1(int64_t v) { return _mm256_set1_epi64x(v); }
	BIMS_AVX2 static I add(I a, I b) { return _mm256_add_epi64(a, b); }
	BIMS_AVX2 static I word(I g) { return _mm256_srli_epi64(g, 6); }
	BIMS_AVX2 static I bit(I g)
	{
		return _mm256_sllv_epi64(_mm256_set1_epi64x(1),
		                         _mm256_and_si256(g, _mm256_set1_epi64x(63)));
	}
	BIMS_AVX2 static M differ(I a, I b)
	{
		return _mm256_xor_si256(_mm256_cmpeq_epi64(a, b),
		                        _mm256_set1_epi32(-1));
	}
	/** m ? a : b */
	BIMS_AVX2 static I select(M m, I a, I b)
	{
		return _mm256_blendv_epi8(b, a, m);
	}
	BIMS_AVX2 static I orI(I a, I b) { return _mm256_or_si256(a, b); }
	/** The lanes of \a v in \a m, packed at \a out (N written); how many. */
	BIMS_AVX2 static size_t compress(M m, I v, int64_t* out)
	{
		// Per 4-bit lane mask, the 32-bit elements to gather, in order.
		alignas(32) static const int32_t kPerm[16][8] = {
		    {0, 1, 2, 3, 4, 5, 6, 7}, {0, 1, 2, 3, 4, 5, 6, 7},
		    {2, 3, 0, 1, 4, 5, 6, 7}, {0, 1, 2, 3, 4, 5, 6, 7},
		    {4, 5, 0, 1, 2, 3, 6, 7}, {0, 1, 4, 5, 2, 3, 6, 7},
		    {2, 3, 4, 5, 0, 1, 6, 7}, {0, 1, 2, 3, 4, 5, 6, 7},
		    {6, 7, 0, 1, 2, 3, 4, 5}, {0, 1, 6, 7, 2, 3, 4, 5},
		    {2, 3, 6, 7, 0, 1, 4, 5}, {0, 1, 2, 3, 6, 7, 4, 5},
		    {4, 5, 6, 7, 0, 1, 2, 3}, {0, 1, 4, 5, 6, 7, 2, 3},
		    {2, 3, 4, 5, 6, 7, 0, 1}, {0, 1, 2, 3, 4, 5, 6, 7}};
		const int k = _mm256_movemask_pd(_mm256_castsi256_pd(m));
		const __m256i p =
		    _mm256_load_si256(reinterpret_cast<const __m256i*>(kPerm[k]));
		_mm256_storeu_si256(reinterpret_cast<__m256i*>(out),
		                    _mm256_permutevar8x32_epi32(v, p));
		return size_t(__builtin_popcount(unsigned(k)));
	}
	BIMS_AVX2 static M lt(D a, D b)
	{
		return _mm256_castpd_si256(_mm256_cmp_pd(a, b, _CMP_LT_OQ));
	}
	BIMS_AVX2 static M le(D a, D b)
	{
		return _mm256_castpd_si256(_mm256_cmp_pd(a, b, _CMP_LE_OQ));
	}
	BIMS_AVX2 static M both(M a, M b) { return _mm256_and_si256(a, b); }
	BIMS_AVX2 static D addIf(D t, M m, D d)
	{
		return _mm256_add_pd(t, _mm256_and_pd(_mm256_castsi256_pd(m), d));
	}
	/** mx ? a : my ? b : c */
	BIMS_AVX2 static I pick(M mx, M my, I a, I b, I c)
	{
		return _mm256_blendv_epi8(_mm256_blendv_epi8(c, b, my), a, mx);
	}
	/** RayBox::step() */
	BIMS_AVX2 static I stepBits(I g, I m, I c)
	{
		return _mm256_or_si256(
		    _mm256_and_si256(_mm256_add_epi64(_mm256_and_si256(g, m), c), m),
		    _mm256_andnot_si256(m, g));
	}
};
#define BIMS_AVX512 __attribute__((target("avx512f,avx512dq")))
// (__m512i is a vector of GCC's extensions: its operators avoid intrinsics
// that GCC 12 flags as maybe uninitialized.)
struct Avx512Ops
{
	static constexpr int N = 8;
	using D = __m512d;
	using I = __m512i;
	using M = __mmask8;
	BIMS_AVX512 static D loadD(const double* p) { return _mm512_load_pd(p); }
	BIMS_AVX512 static I loadI(const int64_t* p)
	{
		return _mm512_load_si512(p);
	}
	BIMS_AVX512 static void storeD(double* p, D v) { _mm512_store_pd(p, v); }
	BIMS_AVX512 static void storeI(int64_t* p, I v)
	{
		_mm512_store_si512(p, v);
	}
	BIMS_AVX512 static I set1(int64_t v) { return _mm512_set1_epi64(v); }
	BIMS_AVX512 static I add(I a, I b) { return a + b; }
	// (Bit indices are below 2^63: the signed shift is the unsigned one.)
	BIMS_AVX512 static I word(I g) { return g >> 6; }
	BIMS_AVX512 static I bit(I g) { return _mm512_set1_epi64(1) << (g & 63); }
	BIMS_AVX512 static M differ(I a, I b)
	{
		return _mm512_cmpneq_epi64_mask(a, b);
	}
	BIMS_AVX512 static I select(M m, I a, I b)
	{
		return _mm512_mask_blend_epi64(m, b, a);
	}
	BIMS_AVX512 static I orI(I a, I b) { return a | b; }
	BIMS_AVX512 static size_t compress(M m, I v, int64_t* out)
	{
		_mm512_storeu_si512(out, _mm512_maskz_compress_epi64(m, v));
		return size_t(__builtin_popcount(unsigned(m)));
	}
	BIMS_AVX512 static M lt(D a, D b)
	{
		return _mm512_cmp_pd_mask(a, b, _CMP_LT_OQ);
	}
	BIMS_AVX512 static M le(D a, D b)
	{
		return _mm512_cmp_pd_mask(a, b, _CMP_LE_OQ);
	}
	BIMS_AVX512 static M both(M a, M b) { return M(a & b); }
	BIMS_AVX512 static D addIf(D t, M m, D d)
	{
		return _mm512_mask_add_pd(t, m, t, d);
	}
	BIMS_AVX512 static I pick(M mx, M my, I a, I b, I c)
	{
		return _mm512_mask_mov_epi64(_mm512_mask_mov_epi64(c, my, b), mx, a);
	}
	BIMS_AVX512 static I stepBits(I g, I m, I c)
	{
		return (((g & m) + c) & m) | (g & ~m);
	}
};

// The walker once per instruction set, with that set as the function's
// target, so that no code outside it uses the set.
#define BIMS_WALK_NAME walk4
#define BIMS_WALK_OPS Avx2Ops
#define BIMS_WALK_TARGET BIMS_AVX2
#include "ray_walk_lanes.inc"
#define BIMS_WALK_NAME walk8
#define BIMS_WALK_OPS Avx512Ops
#define BIMS_WALK_TARGET BIMS_AVX512
#include "ray_walk_lanes.inc"
#endif

}  // namespace

bool rayLanesSupported(RayLanes lanes)
{
	switch (lanes)
	{
		case RayLanes::Best:
		case RayLanes::One:
			return true;
#if defined(BIMS_RAY_LANES_X86)
		case RayLanes::Four:
			return __builtin_cpu_supports("avx2");
		case RayLanes::Eight:
			return __builtin_cpu_supports("avx512f") &&
			       __builtin_cpu_supports("avx512dq");
#endif
		default:
			return false;
	}
}

void markRays(const double a[3], const RayEnd* ends, size_t r0, size_t r1,
              const RayBox& box, BlockStored stored, const void* ctx,
              RayMarks& m, RayLanes lanes)
{
	Runs runs;
	Walk w{a, ends, r0, r1, box, stored, ctx, m, runs};
#if defined(BIMS_RAY_LANES_X86)
	static const RayLanes best =
	    rayLanesSupported(RayLanes::Eight)  ? RayLanes::Eight
	    : rayLanesSupported(RayLanes::Four) ? RayLanes::Four
	                                        : RayLanes::One;
	if (lanes == RayLanes::Best || !rayLanesSupported(lanes)) lanes = best;
	if (lanes == RayLanes::Eight) return walk8(w);
	if (lanes == RayLanes::Four) return walk4(w);
#else
	(void)lanes;
#endif
	walk1(w);
}

void mergeRayMarks(RayMarks& m, const RayMarks& o)
{
	for (const uint32_t b : o.touched)
	{
		for (size_t i = 8 * size_t(b); i < 8 * size_t(b) + 8; ++i)
			m.bits[i] |= o.bits[i];
		if (m.state[b] == RayMarks::kUnknown)
		{
			m.touched.push_back(b);
			m.state[b] = o.state[b];
			m.firstVisit[b] = o.firstVisit[b];
		}
		else if (m.missing(b))
			m.firstVisit[b] = std::min(m.firstVisit[b], o.firstVisit[b]);
	}
}

}  // namespace bims::maps
