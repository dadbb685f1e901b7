#include <bims/common/frames.h>
#include <bims/maps/frame_cloud.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#if defined(__SSE2__) && defined(__x86_64__)
#include <emmintrin.h>
#define BIMS_FRAME_CLOUD_SSE2 1
#endif

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace bims::maps
{
FrameStats& FrameStats::operator+=(const FrameStats& o)
{
	valid += o.valid;
	noDepth += o.noDepth;
	nonFinite += o.nonFinite;
	beyondRange += o.beyondRange;
	outsideExtent += o.outsideExtent;
	overBudget += o.overBudget;
	badPose = badPose || o.badPose;
	return *this;
}

std::string FrameStats::asString() const
{
	std::ostringstream s;
	s << "valid=" << valid << " noDepth=" << noDepth
	  << " nonFinite=" << nonFinite << " beyondRange=" << beyondRange
	  << " outsideExtent=" << outsideExtent << " overBudget=" << overBudget
	  << (badPose ? " badPose" : "");
	return s.str();
}

FrameCloudBuilder::FrameCloudBuilder(const GridParams& p)
{
	setParams(p);
}

void FrameCloudBuilder::setParams(const GridParams& p)
{
	p.validate();
	p_ = p;
}

namespace
{
bool finitePose(const mrpt::poses::CPose3D& T)
{
	for (int i = 0; i < 3; ++i)
	{
		if (!std::isfinite(T.m_coords[i])) return false;
		for (int j = 0; j < 3; ++j)
			if (!std::isfinite(T.getRotationMatrix()(i, j))) return false;
	}
	return true;
}

// Empties the frame; with keepBuffers, the per-reading vectors keep their
// size (the caller overwrites and then shrinks them), so that growing them
// again does not value-initialise what was already there (also cells
// and hits: finishCells() writes and shrinks them).
void resetFrame(FrameCloud& out, bool keepBuffers = false)
{
	if (!keepBuffers)
	{
		out.points_W.clear();
		out.pixel.clear();
		out.cellOfPoint.clear();
		out.depth.clear();
		out.cells.clear();
		out.hits.clear();
	}
	out.stats = FrameStats();
}

// floor(v) for |v| < 2^31 (the keys of readings within the extent), with
// fewer instructions than std::floor on any double.
inline int32_t floorSmall(double v)
{
	const int32_t i = static_cast<int32_t>(v);
	return i - int32_t(v < double(i));
}

// Grows a vector to at least n elements without touching the elements it
// already has (a resize() after clear() would value-initialise all n).
template <class T>
T* growTo(std::vector<T>& v, size_t n)
{
	if (v.size() < n) v.resize(n);
	return v.data();
}
// The readings written so far: the output buffers and the run state.
struct Readings
{
	mrpt::math::TPoint3Df* pts;
	uint32_t* pix;
	uint32_t* runOf;
	uint64_t* runKey;
	uint32_t* runStart;
	size_t w = 0, r = 0, noDepth = 0;
	uint64_t prev = ~uint64_t(0);  // no packed key yet
};

// One reading of the fast path (raw <= the row's rawFast; raw 0 is counted
// as no depth and not kept): its slots are written whether kept or not, and
// the counts advance without a branch.
inline void addFast(Readings& o, uint64_t key, uint32_t pixel, bool keep)
{
	o.runKey[o.r] = key;
	o.runStart[o.r] = uint32_t(o.w);
	o.r += keep & (key != o.prev);
	o.prev = keep ? key : o.prev;
	o.runOf[o.w] = uint32_t(o.r - 1);
	o.pix[o.w] = pixel;
	o.w += keep;
	o.noDepth += !keep;
}

#ifdef BIMS_FRAME_CLOUD_SSE2
// floor(v) of two doubles with |v| < 2^31 (SSE2: truncate, then one less
// where the truncation is above v), in the two low int32 lanes.
inline __m128i floorSmall2(__m128d v)
{
	const __m128i i = _mm_cvttpd_epi32(v);
	const __m128d above = _mm_cmplt_pd(v, _mm_cvtepi32_pd(i));
	return _mm_add_epi32(
	    i, _mm_shuffle_epi32(_mm_castpd_si128(above), _MM_SHUFFLE(3, 3, 2, 0)));
}

// The packed keys (packKey) of two readings, floor(fl(p) / voxel) per axis
// computed as coordToIndex does: the float coordinate in double times the
// inverse voxel size.
inline __m128i packKeys2(__m128 fx, __m128 fy, __m128 fz, __m128d inv)
{
	const __m128i off = _mm_set1_epi32(1 << 20);
	const __m128i zero = _mm_setzero_si128();
	auto field = [&](__m128 f)
	{
		const __m128i k =
		    _mm_add_epi32(floorSmall2(_mm_mul_pd(_mm_cvtps_pd(f), inv)), off);
		return _mm_unpacklo_epi32(k, zero);  // two uint64
	};
	return _mm_or_si128(_mm_or_si128(_mm_slli_epi64(field(fx), 42),
	                                 _mm_slli_epi64(field(fy), 21)),
	                    field(fz));
}

// The fast path of one row: pairs of pixels whose raw values are both <=
// rawFast are unprojected, converted to float and keyed two at a time in
// SSE2 doubles (the same operations, in the same order, as the scalar
// code); any other pixel goes to other(u) (which updates o itself).
template <class Other>
void fastRow(const uint16_t* raw, int W, uint32_t rawFast, uint32_t rowPix,
             const double* colX, const double* colY, const double* colZ,
             const double b[3], const mrpt::math::TPoint3D& t, double units,
             double inv, float* depthRow, Readings& o, Other&& other)
{
	const __m128d by = _mm_set1_pd(b[0]), bz = _mm_set1_pd(b[1]),
	              bw = _mm_set1_pd(b[2]);
	const __m128d tx = _mm_set1_pd(t.x), ty = _mm_set1_pd(t.y),
	              tz = _mm_set1_pd(t.z);
	const __m128d vUnits = _mm_set1_pd(units), vInv = _mm_set1_pd(inv);
	Readings s = o;  // in registers, not aliased by the stores below
	const __m128i zero16 = _mm_setzero_si128();
	int u = 0;
	while (u + 1 < W)
	{
		const uint32_t r0 = raw[u], r1 = raw[u + 1];
		// Eight pixels without depth (a hole, a sparse image) at once: depth
		// 0, counted, nothing else written (their slots would be
		// overwritten by the next reading kept).
		if (r0 == 0 && u + 8 <= W &&
		    _mm_movemask_epi8(_mm_cmpeq_epi16(
		        _mm_loadu_si128(reinterpret_cast<const __m128i*>(raw + u)),
		        zero16)) == 0xFFFF)
		{
			_mm_storeu_ps(depthRow + u, _mm_setzero_ps());
			_mm_storeu_ps(depthRow + u + 4, _mm_setzero_ps());
			s.noDepth += 8;
			u += 8;
			continue;
		}
		if (r0 > rawFast || r1 > rawFast)
		{
			o = s;
			other(u);
			s = o;
			++u;
			continue;
		}
		const __m128d d = _mm_mul_pd(
		    _mm_cvtepi32_pd(_mm_unpacklo_epi32(_mm_cvtsi32_si128(int(r0)),
		                                       _mm_cvtsi32_si128(int(r1)))),
		    vUnits);
		const __m128d px = _mm_add_pd(
		    tx, _mm_mul_pd(d, _mm_add_pd(_mm_loadu_pd(colX + u), by)));
		const __m128d py = _mm_add_pd(
		    ty, _mm_mul_pd(d, _mm_add_pd(_mm_loadu_pd(colY + u), bz)));
		const __m128d pz = _mm_add_pd(
		    tz, _mm_mul_pd(d, _mm_add_pd(_mm_loadu_pd(colZ + u), bw)));
		const __m128 fx = _mm_cvtpd_ps(px), fy = _mm_cvtpd_ps(py),
		             fz = _mm_cvtpd_ps(pz);
		const __m128i keys = packKeys2(fx, fy, fz, vInv);
		// d is 0 for raw 0: the depth of a pixel not kept.
		_mm_storel_pi(reinterpret_cast<__m64*>(depthRow + u), _mm_cvtpd_ps(d));
		// (x0 y0 z0 z1) and (x1 y1 z1 z1): 16-byte stores, the fourth float
		// overwritten by the next reading (the buffer has a slot more).
		const __m128 xy = _mm_unpacklo_ps(fx, fy);
		const __m128 p0 = _mm_movelh_ps(xy, fz);
		const __m128 p1 = _mm_shuffle_ps(xy, fz, _MM_SHUFFLE(1, 1, 3, 2));
		const uint64_t k0 = uint64_t(_mm_cvtsi128_si64(keys));
		const uint64_t k1 =
		    uint64_t(_mm_cvtsi128_si64(_mm_unpackhi_epi64(keys, keys)));
		_mm_storeu_ps(reinterpret_cast<float*>(s.pts + s.w), p0);
		addFast(s, k0, rowPix + uint32_t(u), r0 != 0);
		_mm_storeu_ps(reinterpret_cast<float*>(s.pts + s.w), p1);
		addFast(s, k1, rowPix + uint32_t(u) + 1, r1 != 0);
		u += 2;
	}
	o = s;
	if (u < W) other(u);
}
#else
// Without SSE2 (not x86-64): every pixel through the scalar code.
template <class Other>
void fastRow(const uint16_t*, int W, uint32_t, uint32_t, const double*,
             const double*, const double*, const double*,
             const mrpt::math::TPoint3D&, double, double, float*, Readings&,
             Other&& other)
{
	for (int u = 0; u < W; ++u) other(u);
}
#endif
}  // namespace

// The checks of one reading in {W} and its voxel key: the reading is kept
// (returns true) or counted by the first reason that rejects it.
struct FrameCloudBuilder::Keyer
{
	double inv, ext, maxR2;
	mrpt::math::TPoint3D o;
	FrameStats& st;

	bool operator()(const mrpt::math::TPoint3Df& p, VoxelKey& k) const
	{
		if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
		{
			st.nonFinite++;
			return false;
		}
		if (std::abs(p.x) > ext || std::abs(p.y) > ext || std::abs(p.z) > ext)
		{
			st.outsideExtent++;
			return false;
		}
		const double dx = p.x - o.x, dy = p.y - o.y, dz = p.z - o.z;
		if (dx * dx + dy * dy + dz * dz > maxR2)
		{
			st.beyondRange++;
			return false;
		}
		k = {coordToIndex(p.x, inv), coordToIndex(p.y, inv),
		     coordToIndex(p.z, inv)};
		return true;
	}
};

void FrameCloudBuilder::build(const mrpt::obs::CObservation3DRangeScan& scan,
                              const mrpt::poses::CPose3D& T_WS, FrameCloud& out)
{
	const auto& cam = scan.cameraParams;
	build(scan, sensors::PinholeCamera::of(cam), T_WS + bims::T_SC(), out);
}

void FrameCloudBuilder::build(const mrpt::obs::CObservation3DRangeScan& scan,
                              const sensors::PinholeCamera& cam,
                              const mrpt::poses::CPose3D& T_WC, FrameCloud& out)
{
	build(depthImageOf(scan), cam, T_WC, out);
}

namespace
{
// The input checks of build(): an empty image or a camera model that does
// not fit it is an error (after which the readings of the last frame go).
void checkDepthInput(const DepthImage& img, const sensors::PinholeCamera& cam,
                     FrameCloud& out)
{
	auto fail = [&](const std::string& what)
	{
		resetFrame(out);
		throw std::invalid_argument("bims::maps::FrameCloudBuilder: scan '" +
		                            img.label + "'" + what);
	};
	if (img.empty()) fail(" has no range image");
	const int W = img.width, H = img.height;
	if (cam.width != W || cam.height != H)
		fail(": camera size " + std::to_string(cam.width) + "x" +
		     std::to_string(cam.height) + " differs from the range image " +
		     std::to_string(W) + "x" + std::to_string(H));
	if (!(cam.fx > 0 && cam.fy > 0)) fail(": focal lengths must be > 0");
}

// What every row of build() reads: the image's units, the camera, the pose,
// the per-column terms and the bound of the exact fast path.
struct CloudUnprojection
{
	double units, maxR, inv;
	bool isDepth;
	double ify, cy;
	const mrpt::math::CMatrixDouble33& R;  ///< R_WC
	mrpt::math::TPoint3D t;                ///< t_WC
	// Per column: 1 + xn^2 and xn * R.col0 (the terms of the unprojection
	// that depend on u only), one array each, and the largest colA.
	const double *colA, *colX, *colY, *colZ;
	double maxA;
	// Fast path, exact: a reading whose distance d * norm is safely below
	// max_range (with the largest norm of its row, fl() being monotonic) is
	// kept by every check of the plain path (range in double, then in float;
	// finite and within the extent when the whole sensor range is), so these
	// checks and the square root (depth images) are skipped for it.
	bool fast;
	double rSafe;
	// The fast branch also takes the pixels without depth (raw 0: d = 0, the
	// sensor origin, inside the extent), which are not kept; its depth
	// scale is 0 when there is no fast path (raw 0 is all it takes then).
	double unitsFast;
};

// Fills \a colTab with the per-column terms of a W-pixel row (4 arrays of
// W) and returns the largest 1 + xn^2.
double fillColumnTerms(std::vector<double>& colTab, int W, double cx,
                       double ifx, const mrpt::math::CMatrixDouble33& R)
{
	colTab.resize(4 * size_t(W));
	double* colA = colTab.data();
	double* colX = colA + W;
	double* colY = colX + W;
	double* colZ = colY + W;
	double maxA = 1;
	for (int u = 0; u < W; ++u)
	{
		const double xn = (u - cx) * ifx;
		colA[u] = 1 + xn * xn;
		colX[u] = xn * R(0, 0);
		colY[u] = xn * R(1, 0);
		colZ[u] = xn * R(2, 0);
		maxA = std::max(maxA, colA[u]);
	}
	return maxA;
}

CloudUnprojection cloudUnprojection(const DepthImage& img,
                                    const sensors::PinholeCamera& cam,
                                    const mrpt::poses::CPose3D& T_WC,
                                    const GridParams& p,
                                    std::vector<double>& colTab)
{
	const auto& R = T_WC.getRotationMatrix();
	const mrpt::math::TPoint3D t = T_WC.translation();
	const int W = img.width;
	const double maxA = fillColumnTerms(colTab, W, cam.cx, 1 / cam.fx, R);
	const double units = img.units, maxR = p.max_range;
	const double tMax = std::max({std::abs(t.x), std::abs(t.y), std::abs(t.z)});
	const double rSafe =
	    maxR - (4 * (tMax + maxR) * std::ldexp(1.0, -24) + 1e-9 * maxR);
	const bool fast = img.isDepth && std::isfinite(units) && units >= 1e-300 &&
	                  std::isfinite(units * 65535.0) &&
	                  (tMax + maxR) * (1 + 1e-6) + 1 < p.extent && rSafe > 0;
	const double* colA = colTab.data();
	return {units,
	        maxR,
	        1.0 / p.voxel_size,
	        img.isDepth,
	        1 / cam.fy,
	        cam.cy,
	        R,
	        t,
	        colA,
	        colA + W,
	        colA + 2 * W,
	        colA + 3 * W,
	        maxA,
	        fast,
	        rSafe,
	        fast ? units : 0.0};
}

// The largest raw value of the fast path in a row whose largest norm is
// \a normMax: d * normMax (d = raw * units, exact) is monotonic in raw.
uint32_t rowRawFast(const CloudUnprojection& un, double normMax)
{
	if (!un.fast) return 0;
	auto isFast = [&](uint32_t raw)
	{ return double(raw) * un.units * normMax <= un.rSafe; };
	const double e = std::floor(un.rSafe / (un.units * normMax));
	uint32_t rawFast = uint32_t(std::clamp(e, 0.0, 65535.0));
	while (rawFast < 65535 && isFast(rawFast + 1)) ++rawFast;
	while (rawFast > 0 && !isFast(rawFast)) --rawFast;
	return rawFast;
}

// Row v of the image into the readings \a o and the depth row: runs, a slot
// written for every reading of the fast path and kept (r advanced) only
// where a kept reading's voxel changes, without a branch on it; each kept
// reading notes its run (runOf, the future cellOfPoint).
template <class KeyerT>
void unprojectRow(const DepthImage& img, int v, const CloudUnprojection& un,
                  const KeyerT& keyer, float* depth, Readings& o,
                  FrameStats& st)
{
	const int W = img.width;
	const double yn = (v - un.cy) * un.ify;
	const double yn2 = yn * yn;
	const uint32_t rawFast = rowRawFast(un, std::sqrt(un.maxA + yn2));
	const auto& R = un.R;
	const mrpt::math::TPoint3D& t = un.t;
	const double *colX = un.colX, *colY = un.colY, *colZ = un.colZ;
	// Ray direction in {W} for depth 1: xn*R.col0 + yn*R.col1 + R.col2.
	const double b[3] = {yn * R(0, 1) + R(0, 2), yn * R(1, 1) + R(1, 2),
	                     yn * R(2, 1) + R(2, 2)};
	const uint32_t rowPix = uint32_t(size_t(v) * W);
	const uint16_t* rawRow = img.row(v);
	float* depthRow = depth + rowPix;
	// One pixel, any case (the fast path in scalar code).
	auto pixel = [&](int u)
	{
		const uint32_t raw = rawRow[u];
		mrpt::math::TPoint3Df p;
		if (raw <= rawFast)
		{
			const double d = double(raw) * un.unitsFast;
			p = {float(t.x + d * (colX[u] + b[0])),
			     float(t.y + d * (colY[u] + b[1])),
			     float(t.z + d * (colZ[u] + b[2]))};
			depthRow[u] = float(d);  // 0 for raw 0
			o.pts[o.w] = p;
			addFast(o,
			        packKey(floorSmall(p.x * un.inv), floorSmall(p.y * un.inv),
			                floorSmall(p.z * un.inv)),
			        rowPix + uint32_t(u), raw != 0);
			return;
		}
		depthRow[u] = 0;
		const double norm = std::sqrt(un.colA[u] + yn2);
		double d = raw * un.units;
		if (!un.isDepth) d /= norm;
		if (!(d > 0) || !std::isfinite(d))
		{
			st.nonFinite++;
			return;
		}
		if (d * norm > un.maxR)
		{
			st.beyondRange++;
			return;
		}
		p = {float(t.x + d * (colX[u] + b[0])),
		     float(t.y + d * (colY[u] + b[1])),
		     float(t.z + d * (colZ[u] + b[2]))};
		VoxelKey k;
		if (!keyer(p, k)) return;
		depthRow[u] = float(d);
		o.pts[o.w] = p;
		addFast(o, packKey(k), rowPix + uint32_t(u), true);
	};
	fastRow(rawRow, W, rawFast, rowPix, colX, colY, colZ, b, t, un.unitsFast,
	        un.inv, depthRow, o, pixel);
}
}  // namespace

void FrameCloudBuilder::build(const DepthImage& img,
                              const sensors::PinholeCamera& cam,
                              const mrpt::poses::CPose3D& T_WC, FrameCloud& out)
{
	resetFrame(out, true);
	out.voxel_size = p_.voxel_size;
	out.timestamp = img.timestamp;
	checkDepthInput(img, cam, out);
	const int W = img.width, H = img.height;
	out.K = cam;
	if (!finitePose(T_WC))
	{
		resetFrame(out);
		out.stats.badPose = true;
		out.K = {};
		return;
	}
	out.T_WC = T_WC;
	out.origin_W = out.T_WC.translation();
	const size_t N = size_t(W) * H;
	// Every pixel's depth, reading and run slot is written below before it
	// is read (depth: 0 where no reading is kept), so the buffers only grow
	// (one slot more than readings) and are shrunk to the kept readings.
	out.depth.resize(N);
	// A slot more for the 16-byte stores of points (see fastRow()).
	Readings o{growTo(out.points_W, N + 1), growTo(out.pixel, N),
	           growTo(out.cellOfPoint, N), growTo(runKey_, N + 1),
	           growTo(runStart_, N + 1)};
	const CloudUnprojection un =
	    cloudUnprojection(img, cam, out.T_WC, p_, colTab_);
	const Keyer keyer{un.inv, p_.extent, p_.max_range * p_.max_range, un.t,
	                  out.stats};
	for (int v = 0; v < H; ++v)
		unprojectRow(img, v, un, keyer, out.depth.data(), o, out.stats);
	const size_t w = o.w;
	out.stats.noDepth += o.noDepth;
	nRuns_ = o.r;
	out.points_W.resize(w);
	out.pixel.resize(w);
	finishCells(out);
}

void FrameCloudBuilder::buildFromPoints(
    const std::vector<mrpt::math::TPoint3Df>& points_W,
    const std::vector<uint32_t>& pixels, const mrpt::math::TPoint3D& origin_W,
    FrameCloud& out, const sensors::PinholeCamera& K)
{
	resetFrame(out);
	out.voxel_size = p_.voxel_size;
	out.K = K;
	out.origin_W = origin_W;
	out.T_WC =
	    mrpt::poses::CPose3D(origin_W.x, origin_W.y, origin_W.z, 0, 0, 0);
	if (!pixels.empty() && pixels.size() != points_W.size())
		throw std::invalid_argument(
		    "bims::maps::FrameCloudBuilder::buildFromPoints: " +
		    std::to_string(pixels.size()) + " pixel indices for " +
		    std::to_string(points_W.size()) + " points");
	if (!(std::isfinite(origin_W.x) && std::isfinite(origin_W.y) &&
	      std::isfinite(origin_W.z)))
	{
		out.stats.badPose = true;
		return;
	}
	out.points_W = points_W;
	if (pixels.empty())
	{
		out.pixel.resize(points_W.size());
		for (size_t i = 0; i < points_W.size(); ++i) out.pixel[i] = uint32_t(i);
	}
	else
		out.pixel = pixels;
	// Without a pinhole model (K.width == 0) no depth image is kept.
	keyPoints(out);
}

// Keeps the readings of out.points_W that pass the checks (in place) and
// splits them into runs of consecutive readings in one voxel.
void FrameCloudBuilder::keyPoints(FrameCloud& out)
{
	Keyer keyer{1.0 / p_.voxel_size, p_.extent, p_.max_range * p_.max_range,
	            out.origin_W, out.stats};
	uint64_t prev = ~uint64_t(0);  // no packed key
	const size_t n = out.points_W.size();
	uint64_t* runKey = growTo(runKey_, n + 1);
	uint32_t* runStart = growTo(runStart_, n + 1);
	uint32_t* runOf = growTo(out.cellOfPoint, n);
	size_t r = 0;
	size_t w = 0;
	for (size_t i = 0; i < n; ++i)
	{
		const mrpt::math::TPoint3Df p = out.points_W[i];
		VoxelKey k;
		if (!keyer(p, k))
		{
			// A reading dropped while keying must not count as measured
			// depth.
			if (!out.depth.empty()) out.depth[out.pixel[i]] = 0;
			continue;
		}
		const uint64_t key = packKey(k);
		runKey[r] = key;
		runStart[r] = uint32_t(w);
		r += key != prev;
		prev = key;
		runOf[w] = uint32_t(r - 1);
		out.points_W[w] = p;
		out.pixel[w] = out.pixel[i];
		++w;
	}
	nRuns_ = r;
	out.points_W.resize(w);
	out.pixel.resize(w);
	finishCells(out);
}

namespace
{
unsigned bitWidth(uint64_t v)
{
	unsigned b = 0;
	while (v >> b) ++b;
	return b;
}

// LSD radix sort of 64-bit values on their bits [lowBit, lowBit + bits)
// (stable), digits of at most 11 bits; the histograms of all digits are
// counted in one pass.
void radixSort(std::vector<uint64_t>& v, std::vector<uint64_t>& tmp,
               unsigned lowBit, unsigned bits)
{
	const size_t n = v.size();
	if (n < 2 || bits == 0) return;
	tmp.resize(n);
	const unsigned passes = std::max(1u, (bits + 10) / 11);
	const unsigned digit = (bits + passes - 1) / passes;
	const size_t buckets = size_t(1) << digit;
	const uint64_t mask = buckets - 1;
	std::vector<uint32_t> count(buckets * passes, 0u);
	for (size_t i = 0; i < n; ++i)
	{
		const uint64_t x = v[i] >> lowBit;
		for (unsigned p = 0; p < passes; ++p)
			count[p * buckets + ((x >> (p * digit)) & mask)]++;
	}
	for (unsigned p = 0; p < passes; ++p)
	{
		uint32_t* c = &count[p * buckets];
		// A digit that is equal for all values needs no pass.
		if (c[(v[0] >> (lowBit + p * digit)) & mask] == n) continue;
		uint32_t sum = 0;
		for (size_t b = 0; b < buckets; ++b)
		{
			const uint32_t t = c[b];
			c[b] = sum;
			sum += t;
		}
		const unsigned shift = lowBit + p * digit;
		for (size_t i = 0; i < n; ++i) tmp[c[(v[i] >> shift) & mask]++] = v[i];
		v.swap(tmp);
	}
}

// The fields of a packed key (bims/maps/voxel_key.h): the coordinates
// offset by 2^20, a multiple of 8, so that a field >> 3 is the block
// offset by 2^17 and a field & 7 the cell's coordinate in its block.
constexpr int32_t kOff = 1 << 20;
constexpr uint64_t kField = (uint64_t(1) << 21) - 1;
inline uint32_t fieldX(uint64_t k)
{
	return uint32_t(k >> 42);
}
inline uint32_t fieldY(uint64_t k)
{
	return uint32_t(k >> 21) & kField;
}
inline uint32_t fieldZ(uint64_t k)
{
	return uint32_t(k) & kField;
}
// Index of a cell in its 8^3 block, x fastest (as in the storage).
inline uint32_t cellInBlock(uint64_t k)
{
	return (fieldX(k) & 7) | ((fieldY(k) & 7) << 3) | ((fieldZ(k) & 7) << 6);
}
constexpr unsigned kCacheBits = 11;

// The entries of finishCells(): each run joins the entry of its key if
// the key is in the cache (direct-mapped, 2^kCacheBits slots), else starts
// one and takes the slot. Without a branch (at 2 cm, a run starts an entry
// as often as not): the next entry's slot is written either way. Returns
// the number of entries.
uint32_t mergeRuns(const uint64_t* __restrict runKey,
                   const uint32_t* __restrict runStart, size_t r,
                   uint64_t* __restrict cache, uint64_t* __restrict eKey,
                   uint32_t* __restrict eHits, uint32_t* __restrict runEntry)
{
	uint32_t nE = 0;
	for (size_t j = 0; j < r; ++j)
	{
		const uint64_t k = runKey[j];
		uint64_t* c = cache + 2 * size_t((k * 0x9E3779B97F4A7C15ull) >>
		                                 (64 - kCacheBits));
		const bool hit = c[0] == k;
		const uint32_t e = hit ? uint32_t(c[1]) : nE;
		eKey[nE] = k;
		eHits[nE] = 0;
		eHits[e] += runStart[j + 1] - runStart[j];
		c[0] = k;
		c[1] = e;
		nE += !hit;
		runEntry[j] = e;
	}
	return nE;
}
}  // namespace

// Merges the runs into entries, then orders the entries by 8^3 block (blocks
// in (x, y, z) lexicographic order) and by cell inside a block (the cell
// index in the block, x fastest, as in the storage): equal keys are the
// frame's distinct cells, already in block order, so that the grids visit
// each storage block once per frame (one hash lookup per block instead of
// per cell, and cache-friendly writes). On entry out.cellOfPoint holds each
// reading's run; on return its cell.
//
// The entries: a run whose key is in a small direct-mapped cache of recent
// keys joins that key's entry, else it starts one (and takes the slot).
// A voxel is hit by runs of several rows (8 on the VGA sim frame at 5 cm),
// so there are far fewer entries than runs to sort; an entry is not always
// a distinct voxel (a key evicted from the cache comes back as a new
// entry): the sort merges equal keys anyway.
void FrameCloudBuilder::finishCells(FrameCloud& out)
{
	const size_t w = out.points_W.size();
	out.stats.valid = w;
	out.cellOfPoint.resize(w);
	if (w == 0)
	{
		out.cells.clear();
		out.hits.clear();
		return;
	}
	const size_t r = nRuns_;
	const uint64_t* runKey = runKey_.data();
	const uint32_t* runStart = runStart_.data();
	runStart_[r] = uint32_t(w);  // the end of the last run
	// Slots of (key, entry), no key in any.
	cache_.assign(size_t(2) << kCacheBits, ~uint64_t(0));
	uint64_t* eKey = growTo(entryKey_, r + 1);
	uint32_t* eHits = growTo(entryHits_, r + 1);
	uint32_t* runEntry = growTo(runEntry_, r);
	const uint32_t nE =
	    mergeRuns(runKey, runStart, r, cache_.data(), eKey, eHits, runEntry);
	nEntries_ = nE;
	// Bounds of the blocks, in the offset coordinates of the packed keys.
	uint32_t lo[3] = {UINT32_MAX, UINT32_MAX, UINT32_MAX};
	uint32_t hi[3] = {0, 0, 0};
	for (size_t j = 0; j < nE; ++j)
	{
		const uint64_t k = eKey[j];
		const uint32_t b[3] = {fieldX(k) >> 3, fieldY(k) >> 3, fieldZ(k) >> 3};
		for (int a = 0; a < 3; ++a)
		{
			lo[a] = std::min(lo[a], b[a]);
			hi[a] = std::max(hi[a], b[a]);
		}
	}
	// At most one cell per entry: written in place, then shrunk.
	growTo(out.cells, nE);
	growTo(out.hits, nE);
	entryCell_.resize(nE);
	const size_t nb[3] = {size_t(hi[0] - lo[0]) + 1, size_t(hi[1] - lo[1]) + 1,
	                      size_t(hi[2] - lo[2]) + 1};
	const double nBlocks = double(nb[0]) * double(nb[1]) * double(nb[2]);
	const bool bucket =
	    nE < kMaxBucketEntries &&
	    nBlocks <=
	        double(std::min<size_t>(4 * size_t(nE) + 65536, size_t(1) << 24));
	const uint32_t nC =
	    bucket ? bucketCells(out, lo, nb) : radixCells(out, lo, hi);
	out.cells.resize(nC);
	out.hits.resize(nC);
	// Each reading's cell, from its run's entry.
	uint32_t* cop = out.cellOfPoint.data();
	const uint32_t* eCell = entryCell_.data();
	for (size_t i = 0; i < w; ++i) cop[i] = eCell[runEntry[cop[i]]];
}

// finishCells() for frames whose bounding box has too many blocks for a
// bucket per block: one radix sort of compact keys (block relative to the
// frame's lowest block, then the cell index in the block, x fastest, as in
// the storage) packed with the entry index.
uint32_t FrameCloudBuilder::radixCells(FrameCloud& out, const uint32_t lo[3],
                                       const uint32_t hi[3])
{
	const size_t n = nEntries_;
	const uint64_t* eKey = entryKey_.data();
	unsigned bits[3];
	for (int a = 0; a < 3; ++a) bits[a] = bitWidth(uint64_t(hi[a] - lo[a]));
	const unsigned idxBits = bitWidth(uint64_t(n - 1));
	// Key fields above the entry index: cell (9 bits), z, y, x blocks.
	const unsigned sz = 9, sy = sz + bits[2], sx = sy + bits[1];
	const unsigned total = sx + bits[0];
	auto compact = [&](uint64_t k)
	{
		return (uint64_t((fieldX(k) >> 3) - lo[0]) << sx) |
		       (uint64_t((fieldY(k) >> 3) - lo[1]) << sy) |
		       (uint64_t((fieldZ(k) >> 3) - lo[2]) << sz) |
		       uint64_t(cellInBlock(k));
	};
	// Sorted (compact key, entry) pairs: packed in one 64-bit value and
	// radix sorted when both fit, else sorted as pairs.
	auto& keys = packed_;
	keys.resize(n);
	const bool packed = total + idxBits <= 64;
	if (packed)
	{
		for (size_t j = 0; j < n; ++j)
			keys[j] = (compact(eKey[j]) << idxBits) | j;
		radixSort(keys, packedTmp_, idxBits, total);
	}
	else
	{
		pairs_.resize(n);
		for (size_t j = 0; j < n; ++j)
			pairs_[j] = {compact(eKey[j]), uint32_t(j)};
		std::sort(pairs_.begin(), pairs_.end());
	}
	const uint64_t idxMask = (uint64_t(1) << idxBits) - 1;
	uint64_t last = ~uint64_t(0);
	uint32_t nC = 0;
	for (size_t j = 0; j < n; ++j)
	{
		const uint64_t key = packed ? keys[j] >> idxBits : pairs_[j].first;
		const uint32_t e =
		    packed ? uint32_t(keys[j] & idxMask) : pairs_[j].second;
		if (key != last)
		{
			out.cells[nC] = unpackKey(eKey[e]);
			out.hits[nC] = 0;
			++nC;
			last = key;
		}
		out.hits[nC - 1] += entryHits_[e];
		entryCell_[e] = nC - 1;
	}
	return nC;
}

// finishCells() with a bucket per block of the frame's bounding box: a
// counting sort of the entries by block (blocks in (x, y, z) lexicographic
// order), then, per block, the cells present in a 512-bit mask, numbered
// in cell-index order (x fastest, as in the storage). An entry is bucketed
// as (entry << 9) | cell in 32 bits (fewer than 2^23 entries).
uint32_t FrameCloudBuilder::bucketCells(FrameCloud& out, const uint32_t lo[3],
                                        const size_t nb[3])
{
	const size_t nE = nEntries_;
	const size_t n = nb[0] * nb[1] * nb[2];
	const uint32_t nb1 = uint32_t(nb[1]), nb2 = uint32_t(nb[2]);
	auto blockOf = [&](uint64_t k)
	{
		return (size_t((fieldX(k) >> 3) - lo[0]) * nb1 +
		        ((fieldY(k) >> 3) - lo[1])) *
		           nb2 +
		       ((fieldZ(k) >> 3) - lo[2]);
	};
	// Entries per block, then the first slot of each block; the scatter
	// below advances start[b] to the end of block b.
	bucketStart_.assign(n, 0);
	uint32_t* start = bucketStart_.data();
	const uint64_t* eKey = entryKey_.data();
	const uint32_t* eHits = entryHits_.data();
	for (size_t j = 0; j < nE; ++j) start[blockOf(eKey[j])]++;
	uint32_t sum = 0;
	for (size_t b = 0; b < n; ++b)
	{
		const uint32_t t = start[b];
		start[b] = sum;
		sum += t;
	}
	uint32_t* byBlock = growTo(byBlock_, nE);
	for (size_t j = 0; j < nE; ++j)
	{
		const uint64_t k = eKey[j];
		byBlock[start[blockOf(k)]++] = (uint32_t(j) << 9) | cellInBlock(k);
	}
	uint32_t cellId[512];
	uint32_t* eCell = entryCell_.data();
	VoxelKey* cells = out.cells.data();
	uint32_t* hits = out.hits.data();
	uint32_t nC = 0;
	uint32_t b0 = 0;
	size_t b = 0;
	for (size_t bx = 0; bx < nb[0]; ++bx)
		for (size_t by = 0; by < nb[1]; ++by)
			for (size_t bz = 0; bz < nb[2]; ++bz, ++b)
			{
				const uint32_t b1 = start[b];
				if (b0 == b1) continue;
				uint64_t present[8] = {0, 0, 0, 0, 0, 0, 0, 0};
				for (uint32_t j = b0; j < b1; ++j)
				{
					const uint32_t c = byBlock[j] & 511;
					present[c >> 6] |= uint64_t(1) << (c & 63);
				}
				// Block origin in voxels (undoing the 2^20 offset).
				const int32_t ox = int32_t((lo[0] + uint32_t(bx)) * 8) - kOff,
				              oy = int32_t((lo[1] + uint32_t(by)) * 8) - kOff,
				              oz = int32_t((lo[2] + uint32_t(bz)) * 8) - kOff;
				for (uint32_t wd = 0; wd < 8; ++wd)
					for (uint64_t m = present[wd]; m; m &= m - 1)
					{
						const uint32_t c =
						    wd * 64 + uint32_t(__builtin_ctzll(m));
						cellId[c] = nC;
						cells[nC].x = ox + int32_t(c & 7);
						cells[nC].y = oy + int32_t((c >> 3) & 7);
						cells[nC].z = oz + int32_t(c >> 6);
						hits[nC] = 0;
						++nC;
					}
				for (uint32_t j = b0; j < b1; ++j)
				{
					const uint32_t e = byBlock[j] >> 9;
					const uint32_t id = cellId[byBlock[j] & 511];
					hits[id] += eHits[e];
					eCell[e] = id;
				}
				b0 = b1;
			}
	return nC;
}

}  // namespace bims::maps
