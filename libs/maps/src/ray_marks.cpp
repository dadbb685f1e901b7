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
/** The slow part of a visit: a block this thread has not looked up, or a
 * block that is not stored. A block no longer needs slow visits once it is
 * stored, or once it is missing and visited by the oldest ray in flight:
 * every later visit by this thread is then of that ray's later steps or of
 * younger rays, with later (ray, step). */
struct Resolver
{
	const RayBox& box;
	BlockStored stored;
	const void* ctx;
	RayMarks& m;

	void visit(uint64_t g, uint32_t ray, uint32_t step, uint32_t oldest)
	{
		const size_t b = size_t(g >> 9);
		uint8_t& st = m.state[b];
		if (st == RayMarks::kUnknown)
		{
			int32_t c[3];
			box.blockCoords(b, c);
			m.touched.push_back(uint32_t(b));
			if (stored(ctx, c[0], c[1], c[2]))
				st = RayMarks::kStored | RayMarks::kResolved;
			else
			{
				st = RayMarks::kMissing;
				m.firstVisit[b] = RayMarks::kNoVisit;
			}
		}
		if (st & RayMarks::kMissing)
		{
			m.firstVisit[b] =
			    std::min(m.firstVisit[b], (uint64_t(ray) << 32) | step);
			if (ray == oldest) st |= RayMarks::kResolved;
		}
	}
};

/** What a walker needs: the rays, the box, the marks. */
struct Walk
{
	const double* a;
	const RayEnd* ends;
	size_t r0, r1;
	const RayBox& box;
	Resolver& res;
};

#if defined(__x86_64__) && defined(__GNUC__)
#define BIMS_RAY_LANES_X86 1
// The vector operations of the walker (ray_walk_lanes.inc) per instruction
// set: N lanes of doubles (D) and 64-bit integers (I), lane masks (M).
struct Sse2Ops
{
	static constexpr int N = 2;
	using D = __m128d;
	using I = __m128i;
	using M = __m128i;
	static D loadD(const double* p) { return _mm_load_pd(p); }
	static I loadI(const int64_t* p)
	{
		return _mm_load_si128(reinterpret_cast<const __m128i*>(p));
	}
	static void storeD(double* p, D v) { _mm_store_pd(p, v); }
	static void storeI(int64_t* p, I v)
	{
		_mm_store_si128(reinterpret_cast<__m128i*>(p), v);
	}
	static I set1(int64_t v) { return _mm_set1_epi64x(v); }
	static void lanes(I v, uint64_t* out)
	{
		out[0] = uint64_t(_mm_cvtsi128_si64(v));
		out[1] = uint64_t(_mm_cvtsi128_si64(_mm_unpackhi_epi64(v, v)));
	}
	static M lt(D a, D b) { return _mm_castpd_si128(_mm_cmplt_pd(a, b)); }
	static M both(M a, M b) { return _mm_and_si128(a, b); }
	static M notFirst(M a, M b) { return _mm_andnot_si128(a, b); }
	static M neither(M a, M b)
	{
		return _mm_xor_si128(_mm_or_si128(a, b), _mm_set1_epi32(-1));
	}
	static D addIf(D t, M m, D d)
	{
		return _mm_add_pd(t, _mm_and_pd(_mm_castsi128_pd(m), d));
	}
	static I pick(M mx, M my, I a, I b, I c)
	{
		return _mm_or_si128(
		    _mm_or_si128(_mm_and_si128(mx, a), _mm_and_si128(my, b)),
		    _mm_andnot_si128(_mm_or_si128(mx, my), c));
	}
	static I stepBits(I g, I m, I c)
	{
		return _mm_or_si128(
		    _mm_and_si128(_mm_add_epi64(_mm_and_si128(g, m), c), m),
		    _mm_andnot_si128(m, g));
	}
};
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
	BIMS_AVX2 static void lanes(I v, uint64_t* out)
	{
		const __m128i lo = _mm256_castsi256_si128(v),
		              hi = _mm256_extracti128_si256(v, 1);
		out[0] = uint64_t(_mm_cvtsi128_si64(lo));
		out[1] = uint64_t(_mm_extract_epi64(lo, 1));
		out[2] = uint64_t(_mm_cvtsi128_si64(hi));
		out[3] = uint64_t(_mm_extract_epi64(hi, 1));
	}
	BIMS_AVX2 static M lt(D a, D b)
	{
		return _mm256_castpd_si256(_mm256_cmp_pd(a, b, _CMP_LT_OQ));
	}
	BIMS_AVX2 static M both(M a, M b) { return _mm256_and_si256(a, b); }
	BIMS_AVX2 static M notFirst(M a, M b) { return _mm256_andnot_si256(a, b); }
	BIMS_AVX2 static M neither(M a, M b)
	{
		return _mm256_xor_si256(_mm256_or_si256(a, b), _mm256_set1_epi32(-1));
	}
	BIMS_AVX2 static D addIf(D t, M m, D d)
	{
		return _mm256_add_pd(t, _mm256_and_pd(_mm256_castsi256_pd(m), d));
	}
	BIMS_AVX2 static I pick(M mx, M my, I a, I b, I c)
	{
		return _mm256_or_si256(
		    _mm256_or_si256(_mm256_and_si256(mx, a), _mm256_and_si256(my, b)),
		    _mm256_andnot_si256(_mm256_or_si256(mx, my), c));
	}
	BIMS_AVX2 static I stepBits(I g, I m, I c)
	{
		return _mm256_or_si256(
		    _mm256_and_si256(_mm256_add_epi64(_mm256_and_si256(g, m), c), m),
		    _mm256_andnot_si256(m, g));
	}
};
#define BIMS_AVX512 __attribute__((target("avx512f,avx512dq")))
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
	// (__m512i is a vector of GCC's extensions: its operators and element
	// reads avoid intrinsics that GCC 12 flags as maybe uninitialized.)
	BIMS_AVX512 static void lanes(I v, uint64_t* out)
	{
		for (int i = 0; i < 8; ++i) out[i] = uint64_t(v[i]);
	}
	BIMS_AVX512 static M lt(D a, D b)
	{
		return _mm512_cmp_pd_mask(a, b, _CMP_LT_OQ);
	}
	BIMS_AVX512 static M both(M a, M b) { return M(a & b); }
	BIMS_AVX512 static M notFirst(M a, M b) { return M(~a & b); }
	BIMS_AVX512 static M neither(M a, M b) { return M(~(a | b)); }
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
#define BIMS_WALK_NAME walk2
#define BIMS_WALK_OPS Sse2Ops
#define BIMS_WALK_TARGET
#include "ray_walk_lanes.inc"
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
		case RayLanes::Two:
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
	Resolver res{box, stored, ctx, m};
	const Walk w{a, ends, r0, r1, box, res};
#if defined(BIMS_RAY_LANES_X86)
	static const RayLanes best = rayLanesSupported(RayLanes::Eight)
	                                 ? RayLanes::Eight
	                             : rayLanesSupported(RayLanes::Four)
	                                 ? RayLanes::Four
	                                 : RayLanes::Two;
	if (lanes == RayLanes::Best || !rayLanesSupported(lanes)) lanes = best;
	if (lanes == RayLanes::Eight) return walk8(w);
	if (lanes == RayLanes::Four) return walk4(w);
	walk2(w);
#else
	(void)lanes;
	for (size_t r = r0; r < r1; ++r)
	{
		uint32_t step = 0;
		traverseRay(a, ends[r].p,
		            [&](int32_t x, int32_t y, int32_t z)
		            {
			            const uint64_t g = box.bitOf(x, y, z);
			            res.visit(g, uint32_t(r), step++, uint32_t(r));
			            m.bits[g >> 6] |= uint64_t(1) << (g & 63);
		            });
	}
#endif
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
