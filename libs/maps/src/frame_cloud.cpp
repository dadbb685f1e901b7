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

// A reading dropped while keying must not count as measured depth.
void dropDepth(FrameCloud& out, size_t i)
{
	if (!out.depth.empty()) out.depth[out.pixel[i]] = 0;
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
}  // namespace

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
	out.depth.assign(size_t(W) * H, 0.f);
	out.points_W.reserve(size_t(W) * H);
	out.pixel.reserve(size_t(W) * H);

	const double units = scan.rangeUnits;
	const double maxR = p_.max_range;
	const double ifx = 1 / cam.fx(), ify = 1 / cam.fy();
	const double cx = cam.cx(), cy = cam.cy();
	for (int v = 0; v < H; ++v)
	{
		const double yn = (v - cy) * ify;
		// Ray direction in {W} for depth 1: xn*R.col0 + yn*R.col1 + R.col2.
		const double by = yn * R(0, 1) + R(0, 2), bz = yn * R(1, 1) + R(1, 2),
		             bw = yn * R(2, 1) + R(2, 2);
		for (int u = 0; u < W; ++u)
		{
			const uint16_t raw = scan.rangeImage(v, u);
			if (raw == 0)
			{
				out.stats.noDepth++;
				continue;
			}
			const double xn = (u - cx) * ifx;
			const double norm = std::sqrt(1 + xn * xn + yn * yn);
			double d = raw * units;
			if (!scan.range_is_depth) d /= norm;
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
			const size_t pix = size_t(v) * W + u;
			out.depth[pix] = float(d);
			out.points_W.emplace_back(float(t.x + d * (xn * R(0, 0) + by)),
			                          float(t.y + d * (xn * R(1, 0) + bz)),
			                          float(t.z + d * (xn * R(2, 0) + bw)));
			out.pixel.push_back(uint32_t(pix));
		}
	}
	keyPoints(out);
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

namespace
{
// LSD radix sort of (key, value) pairs on the low \a bits bits of the keys
// (stable), with digits of at most 12 bits.
void radixSortPairs(std::vector<uint64_t>& keys, std::vector<uint32_t>& vals,
                    std::vector<uint64_t>& keysTmp,
                    std::vector<uint32_t>& valsTmp, unsigned bits)
{
	const size_t n = keys.size();
	keysTmp.resize(n);
	valsTmp.resize(n);
	const unsigned passes = std::max(1u, (bits + 11) / 12);
	const unsigned digit = (bits + passes - 1) / passes;
	const size_t buckets = size_t(1) << digit;
	const uint64_t mask = buckets - 1;
	std::vector<uint32_t> count(buckets);
	for (unsigned p = 0, shift = 0; p < passes; ++p, shift += digit)
	{
		std::fill(count.begin(), count.end(), 0u);
		for (size_t i = 0; i < n; ++i) count[(keys[i] >> shift) & mask]++;
		uint32_t sum = 0;
		for (auto& c : count)
		{
			const uint32_t t = c;
			c = sum;
			sum += t;
		}
		for (size_t i = 0; i < n; ++i)
		{
			const uint32_t d = count[(keys[i] >> shift) & mask]++;
			keysTmp[d] = keys[i];
			valsTmp[d] = vals[i];
		}
		keys.swap(keysTmp);
		vals.swap(valsTmp);
	}
}

unsigned bitWidth(uint64_t v)
{
	unsigned b = 0;
	while (v >> b) ++b;
	return b;
}
}  // namespace

// Keys every valid reading, then orders the readings by 8^3 block (blocks in
// (x, y, z) lexicographic order) and by cell inside a block with a radix
// sort of compact keys: runs of equal keys are the frame's distinct cells,
// already in block order, so that the grids visit each storage block once
// per frame (one hash lookup per block instead of per cell, and
// cache-friendly writes). No hashing per reading.
void FrameCloudBuilder::keyPoints(FrameCloud& out)
{
	const double inv = 1.0 / p_.voxel_size;
	const double ext = p_.extent, maxR2 = p_.max_range * p_.max_range;
	const auto& o = out.origin_W;
	out.cells.clear();
	out.hits.clear();
	const size_t n = out.points_W.size();
	keys_.resize(n);
	size_t w = 0;
	int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX};
	int32_t hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
	for (size_t i = 0; i < n; ++i)
	{
		const auto& p = out.points_W[i];
		if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
		{
			out.stats.nonFinite++;
			dropDepth(out, i);
			continue;
		}
		if (std::abs(p.x) > ext || std::abs(p.y) > ext || std::abs(p.z) > ext)
		{
			out.stats.outsideExtent++;
			dropDepth(out, i);
			continue;
		}
		const double dx = p.x - o.x, dy = p.y - o.y, dz = p.z - o.z;
		if (dx * dx + dy * dy + dz * dz > maxR2)
		{
			out.stats.beyondRange++;
			dropDepth(out, i);
			continue;
		}
		const int32_t k[3] = {coordToIndex(p.x, inv) >> 3,
		                      coordToIndex(p.y, inv) >> 3,
		                      coordToIndex(p.z, inv) >> 3};
		for (int a = 0; a < 3; ++a)
		{
			lo[a] = std::min(lo[a], k[a]);
			hi[a] = std::max(hi[a], k[a]);
		}
		out.points_W[w] = p;
		out.pixel[w] = out.pixel[i];
		++w;
	}
	out.points_W.resize(w);
	out.pixel.resize(w);
	out.cellOfPoint.resize(w);
	out.stats.valid = w;
	if (w == 0) return;
	// Compact key: block coordinates relative to the frame's lowest block,
	// then the cell index inside the block (x fastest), as in the storage.
	unsigned bits[3];
	for (int a = 0; a < 3; ++a) bits[a] = bitWidth(uint64_t(hi[a] - lo[a]));
	const unsigned sz = 9, sy = sz + bits[2], sx = sy + bits[1];
	const unsigned total = sx + bits[0];
	// Neighbouring pixels often fall in one cell: runs of equal keys among
	// consecutive readings are sorted once, with their length.
	keys_.resize(w);
	order_.resize(w);
	runOf_.resize(w);
	runLen_.resize(w);
	size_t r = 0;
	uint64_t prev = ~uint64_t(0);
	for (size_t i = 0; i < w; ++i)
	{
		const auto& p = out.points_W[i];
		const int32_t kx = coordToIndex(p.x, inv), ky = coordToIndex(p.y, inv),
		              kz = coordToIndex(p.z, inv);
		const uint64_t key =
		    (uint64_t((kx >> 3) - lo[0]) << sx) |
		    (uint64_t((ky >> 3) - lo[1]) << sy) |
		    (uint64_t((kz >> 3) - lo[2]) << sz) |
		    uint64_t((kx & 7) | ((ky & 7) << 3) | ((kz & 7) << 6));
		if (i == 0 || key != prev)
		{
			keys_[r] = key;
			order_[r] = uint32_t(r);
			runLen_[r] = 0;
			++r;
			prev = key;
		}
		runOf_[i] = uint32_t(r - 1);
		runLen_[r - 1]++;
	}
	keys_.resize(r);
	order_.resize(r);
	radixSortPairs(keys_, order_, keysTmp_, orderTmp_, total);
	const uint64_t mx = (uint64_t(1) << bits[0]) - 1,
	               my = (uint64_t(1) << bits[1]) - 1,
	               mz = (uint64_t(1) << bits[2]) - 1;
	runCell_.resize(r);
	uint64_t last = ~uint64_t(0);
	for (size_t j = 0; j < r; ++j)
	{
		const uint64_t key = keys_[j];
		if (key != last)
		{
			const int32_t c = int32_t(key & 511);
			out.cells.push_back(
			    {(int32_t((key >> sx) & mx) + lo[0]) * 8 + (c & 7),
			     (int32_t((key >> sy) & my) + lo[1]) * 8 + ((c >> 3) & 7),
			     (int32_t((key >> sz) & mz) + lo[2]) * 8 + (c >> 6)});
			out.hits.push_back(0);
			last = key;
		}
		out.hits.back() += runLen_[order_[j]];
		runCell_[order_[j]] = uint32_t(out.cells.size() - 1);
	}
	for (size_t i = 0; i < w; ++i) out.cellOfPoint[i] = runCell_[runOf_[i]];
}

}  // namespace bims::maps
