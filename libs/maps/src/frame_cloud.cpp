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

// Orders the distinct cells by 8^3 block, then by cell inside the block, so
// that the grids visit each storage block once per frame (one hash lookup
// per block instead of per cell, and cache-friendly writes).
void FrameCloudBuilder::sortCellsByBlock(FrameCloud& out)
{
	const size_t m = out.cells.size();
	order_.resize(m);
	constexpr int64_t o = int64_t(1) << 17;
	for (size_t i = 0; i < m; ++i)
	{
		const auto& k = out.cells[i];
		const uint64_t key =
		    (uint64_t((k.x >> 3) + o) << 45) |
		    (uint64_t((k.y >> 3) + o) << 27) | (uint64_t((k.z >> 3) + o) << 9) |
		    uint64_t((k.x & 7) | ((k.y & 7) << 3) | ((k.z & 7) << 6));
		order_[i] = {key, uint32_t(i)};
	}
	std::sort(order_.begin(), order_.end());
	newIndex_.resize(m);
	cellsTmp_.resize(m);
	hitsTmp_.resize(m);
	for (size_t j = 0; j < m; ++j)
	{
		const uint32_t i = order_[j].second;
		newIndex_[i] = uint32_t(j);
		cellsTmp_[j] = out.cells[i];
		hitsTmp_[j] = out.hits[i];
	}
	out.cells.swap(cellsTmp_);
	out.hits.swap(hitsTmp_);
	for (auto& c : out.cellOfPoint) c = newIndex_[c];
}

void FrameCloudBuilder::keyPoints(FrameCloud& out)
{
	const double inv = 1.0 / p_.voxel_size;
	const double ext = p_.extent, maxR2 = p_.max_range * p_.max_range;
	const auto& o = out.origin_W;
	dedup_.clear();
	out.cells.clear();
	out.hits.clear();
	out.cellOfPoint.resize(out.points_W.size());
	size_t w = 0;
	uint64_t lastKey = FlatHashMap::kEmpty;
	uint32_t lastCell = 0;
	for (size_t i = 0; i < out.points_W.size(); ++i)
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
		const int32_t kx = coordToIndex(p.x, inv), ky = coordToIndex(p.y, inv),
		              kz = coordToIndex(p.z, inv);
		const uint64_t key = packKey(kx, ky, kz);
		if (key != lastKey)
		{
			const auto [idx, inserted] =
			    dedup_.insert(key, uint32_t(out.cells.size()));
			if (inserted)
			{
				out.cells.push_back({kx, ky, kz});
				out.hits.push_back(0);
			}
			lastKey = key;
			lastCell = idx;
		}
		out.hits[lastCell]++;
		out.points_W[w] = p;
		out.pixel[w] = out.pixel[i];
		out.cellOfPoint[w] = lastCell;
		++w;
	}
	out.points_W.resize(w);
	out.pixel.resize(w);
	out.cellOfPoint.resize(w);
	out.stats.valid = w;
	sortCellsByBlock(out);
}

}  // namespace bims::maps
