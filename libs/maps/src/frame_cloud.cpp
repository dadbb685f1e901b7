#include <bims/common/frames.h>
#include <bims/maps/frame_cloud.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace bims::maps
{
size_t PixelMask::count() const
{
	size_t n = 0;
	for (auto v : data) n += v != 0;
	return n;
}

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

void resetFrame(FrameCloud& out)
{
	out.points_W.clear();
	out.pixel.clear();
	out.cellOfPoint.clear();
	out.cells.clear();
	out.hits.clear();
	out.depth.clear();
	out.stats = FrameStats();
}

// floor(v) for |v| < 2^31 (the keys of readings within the extent), with
// fewer instructions than std::floor on any double.
inline int32_t floorSmall(double v)
{
	const int32_t i = static_cast<int32_t>(v);
	return i - int32_t(v < double(i));
}

// Whether a reading in voxel k starts a new run after one in voxel prev
// (without the branches of operator!=: the outcome is unpredictable).
inline bool newRun(const VoxelKey& k, const VoxelKey& prev)
{
	return ((k.x ^ prev.x) | (k.y ^ prev.y) | (k.z ^ prev.z)) != 0;
}

// Grows a vector to at least n elements without touching the elements it
// already has (a resize() after clear() would value-initialise all n).
template <class T>
T* growTo(std::vector<T>& v, size_t n)
{
	if (v.size() < n) v.resize(n);
	return v.data();
}
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
	resetFrame(out);
	out.voxel_size = p_.voxel_size;
	out.timestamp = scan.timestamp;
	if (!scan.hasRangeImage)
		throw std::invalid_argument("bims::maps::FrameCloudBuilder: scan '" +
		                            scan.sensorLabel + "' has no range image");
	const int W = int(scan.rangeImage.cols()), H = int(scan.rangeImage.rows());
	const auto& cam = scan.cameraParams;
	if (int(cam.ncols) != W || int(cam.nrows) != H)
		throw std::invalid_argument(
		    "bims::maps::FrameCloudBuilder: scan '" + scan.sensorLabel +
		    "': cameraParams size " + std::to_string(cam.ncols) + "x" +
		    std::to_string(cam.nrows) + " differs from the range image " +
		    std::to_string(W) + "x" + std::to_string(H));
	if (!(cam.fx() > 0 && cam.fy() > 0))
		throw std::invalid_argument("bims::maps::FrameCloudBuilder: scan '" +
		                            scan.sensorLabel +
		                            "': focal lengths must be > 0");
	out.K = {W, H, cam.fx(), cam.fy(), cam.cx(), cam.cy()};
	if (!finitePose(T_WS))
	{
		out.stats.badPose = true;
		out.K = {};
		return;
	}
	out.T_WC = T_WS + bims::T_SC();
	const auto& R = out.T_WC.getRotationMatrix();
	const mrpt::math::TPoint3D t = out.T_WC.translation();
	out.origin_W = t;
	const size_t N = size_t(W) * H;
	// Every pixel's depth is written below (0 where no reading is kept).
	out.depth.resize(N);
	float* depth = out.depth.data();
	mrpt::math::TPoint3Df* pts = growTo(out.points_W, N);
	uint32_t* pix = growTo(out.pixel, N);

	const double units = scan.rangeUnits;
	const double maxR = p_.max_range;
	const double ifx = 1 / cam.fx(), ify = 1 / cam.fy();
	const double cx = cam.cx(), cy = cam.cy();
	const bool isDepth = scan.range_is_depth;
	// Per column: xn, 1 + xn^2 and xn * R.col0 (the terms of the
	// unprojection that depend on u only, computed as per pixel before).
	col_.resize(size_t(W));
	for (int u = 0; u < W; ++u)
	{
		auto& c = col_[size_t(u)];
		const double xn = (u - cx) * ifx;
		c.a = 1 + xn * xn;
		c.r[0] = xn * R(0, 0);
		c.r[1] = xn * R(1, 0);
		c.r[2] = xn * R(2, 0);
	}
	double maxA = 1;
	for (const auto& c : col_) maxA = std::max(maxA, c.a);
	const double inv = 1.0 / p_.voxel_size;
	Keyer keyer{inv, p_.extent, p_.max_range * p_.max_range, t, out.stats};
	// Fast path, exact: a reading whose distance d * norm is safely below
	// max_range (with the largest norm of its row, fl() being monotonic) is
	// kept by every check of the plain path (range in double, then in float;
	// finite and within the extent when the whole sensor range is), so these
	// checks and the square root (depth images) are skipped for it.
	const double tMax = std::max({std::abs(t.x), std::abs(t.y), std::abs(t.z)});
	const double rSafe =
	    maxR - (4 * (tMax + maxR) * std::ldexp(1.0, -24) + 1e-9 * maxR);
	const bool fast = isDepth && std::isfinite(units) && units >= 1e-300 &&
	                  std::isfinite(units * 65535.0) &&
	                  (tMax + maxR) * (1 + 1e-6) + 1 < p_.extent && rSafe > 0;
	// Runs: a slot is written for every kept reading and kept (r advanced)
	// only where the voxel changes, without a branch on it.
	VoxelKey* runKey = growTo(runKey_, N + 1);
	uint32_t* runStart = growTo(runStart_, N + 1);
	size_t r = 0;
	size_t noDepth = 0;
	VoxelKey prev{INT32_MIN, INT32_MIN, INT32_MIN};
	size_t w = 0;
	for (int v = 0; v < H; ++v)
	{
		const double yn = (v - cy) * ify;
		const double yn2 = yn * yn;
		const double normMax = std::sqrt(maxA + yn2);
		// Ray direction in {W} for depth 1: xn*R.col0 + yn*R.col1 + R.col2.
		const double by = yn * R(0, 1) + R(0, 2), bz = yn * R(1, 1) + R(1, 2),
		             bw = yn * R(2, 1) + R(2, 2);
		const uint32_t rowPix = uint32_t(size_t(v) * W);
		for (int u = 0; u < W; ++u)
		{
			float& dOut = depth[rowPix + u];
			dOut = 0;
			const uint16_t raw = scan.rangeImage(v, u);
			if (raw == 0)
			{
				noDepth++;
				continue;
			}
			const Column& c = col_[size_t(u)];
			double d = raw * units;
			mrpt::math::TPoint3Df p;
			VoxelKey k;
			if (fast && d * normMax <= rSafe)
			{
				p = {float(t.x + d * (c.r[0] + by)),
				     float(t.y + d * (c.r[1] + bz)),
				     float(t.z + d * (c.r[2] + bw))};
				k = {floorSmall(p.x * inv), floorSmall(p.y * inv),
				     floorSmall(p.z * inv)};
			}
			else
			{
				const double norm = std::sqrt(c.a + yn2);
				if (!isDepth) d /= norm;
				if (!(d > 0) || !std::isfinite(d))
				{
					out.stats.nonFinite++;
					continue;
				}
				if (d * norm > maxR)
				{
					out.stats.beyondRange++;
					continue;
				}
				p = {float(t.x + d * (c.r[0] + by)),
				     float(t.y + d * (c.r[1] + bz)),
				     float(t.z + d * (c.r[2] + bw))};
				if (!keyer(p, k)) continue;
			}
			dOut = float(d);
			runKey[r] = k;
			runStart[r] = uint32_t(w);
			r += newRun(k, prev);
			prev = k;
			pts[w] = p;
			pix[w] = rowPix + uint32_t(u);
			++w;
		}
	}
	out.stats.noDepth += noDepth;
	nRuns_ = r;
	out.points_W.resize(w);
	out.pixel.resize(w);
	finishCells(out);
}

void FrameCloudBuilder::buildFromPoints(
    const std::vector<mrpt::math::TPoint3Df>& points_W,
    const std::vector<uint32_t>& pixels, const mrpt::math::TPoint3D& origin_W,
    FrameCloud& out, const Intrinsics& K)
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
	out.cells.clear();
	out.hits.clear();
	VoxelKey prev{INT32_MIN, INT32_MIN, INT32_MIN};
	const size_t n = out.points_W.size();
	VoxelKey* runKey = growTo(runKey_, n + 1);
	uint32_t* runStart = growTo(runStart_, n + 1);
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
		runKey[r] = k;
		runStart[r] = uint32_t(w);
		r += newRun(k, prev);
		prev = k;
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
}  // namespace

// Orders the runs by 8^3 block (blocks in (x, y, z) lexicographic order) and
// by cell inside a block (the cell index in the block, x fastest, as in the
// storage): equal keys are the frame's distinct cells, already in block
// order, so that the grids visit each storage block once per frame (one hash
// lookup per block instead of per cell, and cache-friendly writes). No
// hashing per reading.
void FrameCloudBuilder::finishCells(FrameCloud& out)
{
	const size_t w = out.points_W.size();
	out.stats.valid = w;
	out.cellOfPoint.resize(w);
	out.cells.clear();
	out.hits.clear();
	if (w == 0) return;
	const size_t r = nRuns_;
	runStart_[r] = uint32_t(w);  // the end of the last run
	int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX};
	int32_t hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
	for (size_t j = 0; j < r; ++j)
	{
		const VoxelKey& k = runKey_[j];
		const int32_t b[3] = {k.x >> 3, k.y >> 3, k.z >> 3};
		for (int a = 0; a < 3; ++a)
		{
			lo[a] = std::min(lo[a], b[a]);
			hi[a] = std::max(hi[a], b[a]);
		}
	}
	out.cells.reserve(r);
	out.hits.reserve(r);
	const size_t nb[3] = {size_t(hi[0] - lo[0]) + 1, size_t(hi[1] - lo[1]) + 1,
	                      size_t(hi[2] - lo[2]) + 1};
	const double nBlocks = double(nb[0]) * double(nb[1]) * double(nb[2]);
	if (w < kMaxBucketReadings &&
	    nBlocks <= double(std::min<size_t>(4 * r + 65536, size_t(1) << 24)))
		bucketCells(out, lo, nb);
	else
		radixCells(out, lo, hi);
}

// finishCells() for frames whose bounding box has too many blocks for a
// bucket per block: one radix sort of compact keys (block relative to the
// frame's lowest block, then the cell index in the block, x fastest, as in
// the storage) packed with the run index.
void FrameCloudBuilder::radixCells(FrameCloud& out, const int32_t lo[3],
                                   const int32_t hi[3])
{
	const size_t r = nRuns_;
	runCell_.resize(r);
	unsigned bits[3];
	for (int a = 0; a < 3; ++a) bits[a] = bitWidth(uint64_t(hi[a] - lo[a]));
	const unsigned idxBits = bitWidth(uint64_t(r - 1));
	// Key fields above the run index: cell (9 bits), z, y, x blocks.
	const unsigned sz = 9, sy = sz + bits[2], sx = sy + bits[1];
	const unsigned total = sx + bits[0];
	auto compact = [&](const VoxelKey& k)
	{
		return (uint64_t((k.x >> 3) - lo[0]) << sx) |
		       (uint64_t((k.y >> 3) - lo[1]) << sy) |
		       (uint64_t((k.z >> 3) - lo[2]) << sz) |
		       uint64_t((k.x & 7) | ((k.y & 7) << 3) | ((k.z & 7) << 6));
	};
	// Sorted (compact key, run) pairs: packed in one 64-bit value and radix
	// sorted when both fit, else sorted as pairs.
	auto& keys = packed_;
	keys.resize(r);
	const bool packed = total + idxBits <= 64;
	if (packed)
	{
		for (size_t j = 0; j < r; ++j)
			keys[j] = (compact(runKey_[j]) << idxBits) | j;
		radixSort(keys, packedTmp_, idxBits, total);
	}
	else
	{
		pairs_.resize(r);
		for (size_t j = 0; j < r; ++j)
			pairs_[j] = {compact(runKey_[j]), uint32_t(j)};
		std::sort(pairs_.begin(), pairs_.end());
	}
	const uint64_t idxMask = (uint64_t(1) << idxBits) - 1;
	uint64_t last = ~uint64_t(0);
	for (size_t j = 0; j < r; ++j)
	{
		const uint64_t key = packed ? keys[j] >> idxBits : pairs_[j].first;
		const uint32_t run =
		    packed ? uint32_t(keys[j] & idxMask) : pairs_[j].second;
		if (key != last)
		{
			out.cells.push_back(runKey_[run]);
			out.hits.push_back(0);
			last = key;
		}
		out.hits.back() += runStart_[run + 1] - runStart_[run];
		runCell_[run] = uint32_t(out.cells.size() - 1);
	}
	uint32_t* cop = out.cellOfPoint.data();
	for (size_t j = 0; j < r; ++j)
		std::fill(cop + runStart_[j], cop + runStart_[j + 1], runCell_[j]);
}

// finishCells() with a bucket per block of the frame's bounding box: a
// counting sort of the runs by block (blocks in (x, y, z) lexicographic
// order), then, per block, the cells present in a 512-bit mask, numbered
// in cell-index order (x fastest, as in the storage). A run is bucketed as
// (first reading << 32) | (length << 9) | cell, so that its readings get
// their cell without a second pass over the runs.
void FrameCloudBuilder::bucketCells(FrameCloud& out, const int32_t lo[3],
                                    const size_t nb[3])
{
	const size_t r = nRuns_;
	const size_t n = nb[0] * nb[1] * nb[2];
	auto blockOf = [&](const VoxelKey& k)
	{
		return (size_t((k.x >> 3) - lo[0]) * nb[1] +
		        size_t((k.y >> 3) - lo[1])) *
		           nb[2] +
		       size_t((k.z >> 3) - lo[2]);
	};
	auto cellOf = [](const VoxelKey& k)
	{ return uint32_t((k.x & 7) | ((k.y & 7) << 3) | ((k.z & 7) << 6)); };
	// Runs per block, then the first slot of each block; the scatter below
	// advances start[b] to the end of block b.
	bucketStart_.assign(n, 0);
	uint32_t* start = bucketStart_.data();
	const VoxelKey* runKey = runKey_.data();
	const uint32_t* runStart = runStart_.data();
	for (size_t j = 0; j < r; ++j) start[blockOf(runKey[j])]++;
	uint32_t sum = 0;
	for (size_t b = 0; b < n; ++b)
	{
		const uint32_t t = start[b];
		start[b] = sum;
		sum += t;
	}
	uint64_t* byBlock = growTo(packed_, r);
	for (size_t j = 0; j < r; ++j)
	{
		const VoxelKey& k = runKey[j];
		const uint64_t len = runStart[j + 1] - runStart[j];
		byBlock[start[blockOf(k)]++] =
		    (uint64_t(runStart[j]) << 32) | (len << 9) | cellOf(k);
	}
	uint32_t cellId[512];
	uint32_t* cop = out.cellOfPoint.data();
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
					const uint32_t c = uint32_t(byBlock[j] & 511);
					present[c >> 6] |= uint64_t(1) << (c & 63);
				}
				const int32_t ox = (lo[0] + int32_t(bx)) * 8,
				              oy = (lo[1] + int32_t(by)) * 8,
				              oz = (lo[2] + int32_t(bz)) * 8;
				for (uint32_t wd = 0; wd < 8; ++wd)
					for (uint64_t m = present[wd]; m; m &= m - 1)
					{
						const uint32_t c =
						    wd * 64 + uint32_t(__builtin_ctzll(m));
						cellId[c] = uint32_t(out.cells.size());
						out.cells.push_back({ox + int32_t(c & 7),
						                     oy + int32_t((c >> 3) & 7),
						                     oz + int32_t(c >> 6)});
						out.hits.push_back(0);
					}
				uint32_t* hits = out.hits.data();
				for (uint32_t j = b0; j < b1; ++j)
				{
					const uint64_t e = byBlock[j];
					const uint32_t id = cellId[e & 511];
					const uint32_t first = uint32_t(e >> 32);
					const uint32_t len =
					    uint32_t(e >> 9) & (kMaxBucketReadings - 1);
					hits[id] += len;
					for (uint32_t q = first; q < first + len; ++q) cop[q] = id;
				}
				b0 = b1;
			}
}

}  // namespace bims::maps
