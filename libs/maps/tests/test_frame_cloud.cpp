// FrameCloudBuilder::build() against a plain per-pixel unprojection written
// from its definition (docs/maps.md): the same readings, points, depth
// image, statistics and cells, bit for bit, on random scans that exercise
// every check (zero depth, non-finite, beyond range, outside the extent)
// and the thresholds of the fast path; and the cells of frames whose
// bounding box is too large for a bucket per block.
#include <bims/common/frames.h>
#include <bims/maps/frame_cloud.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <tuple>

#include "test_util.h"

using namespace bims::maps;

namespace
{
struct Plain
{
	std::vector<mrpt::math::TPoint3Df> pts;
	std::vector<uint32_t> pixel;
	std::vector<float> depth;
	FrameStats st;
};

// The definition: per pixel, depth or range to depth along the optical
// axis, range check, point in {W} (float), then the checks of the float
// point (finite, extent, range) in this order.
Plain plainBuild(const mrpt::obs::CObservation3DRangeScan& s,
                 const mrpt::poses::CPose3D& T_WS, const GridParams& p)
{
	Plain out;
	const int W = int(s.rangeImage.cols()), H = int(s.rangeImage.rows());
	const mrpt::poses::CPose3D T_WC = T_WS + bims::T_SC();
	const auto& R = T_WC.getRotationMatrix();
	const mrpt::math::TPoint3D t = T_WC.translation();
	const auto& c = s.cameraParams;
	out.depth.assign(size_t(W) * H, 0.f);
	for (int v = 0; v < H; ++v)
		for (int u = 0; u < W; ++u)
		{
			const uint16_t raw = s.rangeImage(v, u);
			if (raw == 0)
			{
				out.st.noDepth++;
				continue;
			}
			const double xn = (u - c.cx()) * (1 / c.fx());
			const double yn = (v - c.cy()) * (1 / c.fy());
			const double norm = std::sqrt(1 + xn * xn + yn * yn);
			double d = raw * double(s.rangeUnits);
			if (!s.range_is_depth) d /= norm;
			if (!(d > 0) || !std::isfinite(d))
			{
				out.st.nonFinite++;
				continue;
			}
			if (d * norm > p.max_range)
			{
				out.st.beyondRange++;
				continue;
			}
			const mrpt::math::TPoint3Df q(
			    float(t.x + d * (xn * R(0, 0) + (yn * R(0, 1) + R(0, 2)))),
			    float(t.y + d * (xn * R(1, 0) + (yn * R(1, 1) + R(1, 2)))),
			    float(t.z + d * (xn * R(2, 0) + (yn * R(2, 1) + R(2, 2)))));
			if (!(std::isfinite(q.x) && std::isfinite(q.y) &&
			      std::isfinite(q.z)))
			{
				out.st.nonFinite++;
				continue;
			}
			if (std::abs(q.x) > p.extent || std::abs(q.y) > p.extent ||
			    std::abs(q.z) > p.extent)
			{
				out.st.outsideExtent++;
				continue;
			}
			const double dx = q.x - t.x, dy = q.y - t.y, dz = q.z - t.z;
			if (dx * dx + dy * dy + dz * dz > p.max_range * p.max_range)
			{
				out.st.beyondRange++;
				continue;
			}
			out.pts.push_back(q);
			out.pixel.push_back(uint32_t(v * W + u));
			out.depth[size_t(v) * W + u] = float(d);
		}
	out.st.valid = out.pts.size();
	return out;
}

bool sameBits(float a, float b)
{
	return std::memcmp(&a, &b, sizeof a) == 0;
}

// Cells, hits and cellOfPoint of \a f against a std::map of the voxels of
// its readings, in block order then cell order inside a block.
void expectCellsOfReadings(const FrameCloud& f, double voxel)
{
	auto order = [](const VoxelKey& k)
	{
		return std::make_tuple(k.x >> 3, k.y >> 3, k.z >> 3, k.z & 7, k.y & 7,
		                       k.x & 7);
	};
	std::map<decltype(order(VoxelKey())), uint32_t> ref;
	const double inv = 1 / voxel;
	ASSERT_EQ(f.cellOfPoint.size(), f.numPoints());
	for (size_t i = 0; i < f.numPoints(); ++i)
	{
		const auto& q = f.points_W[i];
		const VoxelKey k{coordToIndex(q.x, inv), coordToIndex(q.y, inv),
		                 coordToIndex(q.z, inv)};
		ref[order(k)]++;
		ASSERT_LT(f.cellOfPoint[i], f.numCells());
		ASSERT_EQ(f.cells[f.cellOfPoint[i]], k) << "reading " << i;
	}
	ASSERT_EQ(f.numCells(), ref.size());
	ASSERT_EQ(f.hits.size(), ref.size());
	size_t c = 0;
	for (const auto& [o, n] : ref)
	{
		ASSERT_EQ(order(f.cells[c]), o) << "cell " << c;
		ASSERT_EQ(f.hits[c], n) << "cell " << c;
		++c;
	}
}

// \a f equals the definition \a ref: the stats, every reading's pixel,
// point and depth bit for bit, and its cells (expectCellsOfReadings).
void expectSameAsPlain(const FrameCloud& f, const Plain& ref, double voxel,
                       int trial)
{
	ASSERT_EQ(f.stats.noDepth, ref.st.noDepth) << trial;
	ASSERT_EQ(f.stats.nonFinite, ref.st.nonFinite) << trial;
	ASSERT_EQ(f.stats.beyondRange, ref.st.beyondRange) << trial;
	ASSERT_EQ(f.stats.outsideExtent, ref.st.outsideExtent) << trial;
	ASSERT_EQ(f.stats.valid, ref.st.valid) << trial;
	ASSERT_EQ(f.numPoints(), ref.pts.size()) << trial;
	ASSERT_EQ(f.pixel.size(), ref.pixel.size()) << trial;
	ASSERT_TRUE(std::equal(f.pixel.begin(), f.pixel.end(), ref.pixel.begin()))
	    << trial;
	for (size_t i = 0; i < ref.pts.size(); ++i)
		ASSERT_TRUE(sameBits(f.points_W[i].x, ref.pts[i].x) &&
		            sameBits(f.points_W[i].y, ref.pts[i].y) &&
		            sameBits(f.points_W[i].z, ref.pts[i].z))
		    << trial << " reading " << i;
	ASSERT_EQ(f.depth.size(), ref.depth.size());
	for (size_t i = 0; i < ref.depth.size(); ++i)
		ASSERT_TRUE(sameBits(f.depth[i], ref.depth[i]))
		    << trial << " pixel " << i;
	expectCellsOfReadings(f, voxel);
}

mrpt::obs::CObservation3DRangeScan::Ptr randomScan(std::mt19937& rng, int W,
                                                   int H, float units,
                                                   bool isDepth,
                                                   uint16_t maxRaw)
{
	auto s = mrpt::obs::CObservation3DRangeScan::Create();
	s->hasRangeImage = true;
	s->range_is_depth = isDepth;
	s->rangeUnits = units;
	s->rangeImage_setSize(H, W);
	s->cameraParams.ncols = W;
	s->cameraParams.nrows = H;
	std::uniform_real_distribution<double> U(0, 1);
	s->cameraParams.setIntrinsicParamsFromValues(
	    W * (0.6 + U(rng)), W * (0.6 + U(rng)), W * (0.3 + 0.4 * U(rng)),
	    H * (0.3 + 0.4 * U(rng)));
	// Smooth surfaces (runs of equal voxels) with holes and outliers.
	const double a = U(rng), b = U(rng);
	for (int v = 0; v < H; ++v)
		for (int u = 0; u < W; ++u)
		{
			const double r = U(rng);
			double z = 0.5 + 0.5 * (1 + std::sin(a * u * 0.2 + b * v * 0.1));
			if (r < 0.08)
				z = 0;
			else if (r < 0.12)
				z = U(rng) * 2;
			s->rangeImage(v, u) =
			    uint16_t(std::min<double>(maxRaw, z / 2 * maxRaw));
		}
	return s;
}
}  // namespace

TEST(FrameCloud, BuildFromAScanEqualsThePlainUnprojectionBitForBit)
{
	std::mt19937 rng(11);
	std::uniform_real_distribution<double> U(-1, 1);
	size_t fast = 0, checked[5] = {0, 0, 0, 0, 0};
	for (int trial = 0; trial < 120; ++trial)
	{
		GridParams p = test::paperGrids();
		p.voxel_size = trial % 3 == 0 ? 0.02 : (trial % 3 == 1 ? 0.05 : 0.3);
		const int kind = trial % 6;
		float units = 1.0f / 5000;
		bool isDepth = trial % 2 == 0;
		double tScale = 3;
		// Raw values up to ~2x max_range: readings on both sides of it.
		p.max_range = 2 + 3 * (U(rng) + 1);
		uint16_t maxRaw = uint16_t(std::min(65535.0, 2 * p.max_range / units));
		if (kind == 1) p.extent = 2.5;    // readings outside the extent
		if (kind == 2) units = INFINITY;  // non-finite depths
		if (kind == 3)
		{
			// Far from the origin: float rounding of the points matters
			// for the range check in float.
			tScale = 400;
			p.extent = 450;
		}
		if (kind >= 3) isDepth = (trial / 6) % 3 != 0;
		// Narrow images too: the fast path bounds a reading's distance
		// with the largest ray norm of its row, close to its own then.
		const bool narrow = kind >= 3 && (trial / 6) % 2 == 0;
		const int W = narrow ? 1 + int(rng() % 3) : 48 + int(rng() % 40),
		          H = narrow ? 2000 : 36 + int(rng() % 30);
		const auto scan = randomScan(rng, W, H, units, isDepth, maxRaw);
		if (kind == 3 || kind == 5)
		{
			// Readings at max_range to +-1 unit: both range checks (in
			// double and on the float point) decide.
			const auto& c = scan->cameraParams;
			for (int v = 0; v < H; ++v)
				for (int u = 0; u < W; ++u)
				{
					const double xn = (u - c.cx()) * (1 / c.fx());
					const double yn = (v - c.cy()) * (1 / c.fy());
					const double norm = std::sqrt(1 + xn * xn + yn * yn);
					const double r = std::round(
					    p.max_range / (units * (isDepth ? norm : 1.0)));
					if (rng() % 2)
						scan->rangeImage(v, u) = uint16_t(std::clamp(
						    r + double(int(rng() % 3) - 1), 1.0, 65535.0));
				}
		}
		const mrpt::poses::CPose3D T_WS(tScale * U(rng), tScale * U(rng),
		                                tScale * U(rng), 3 * U(rng),
		                                1.5 * U(rng), 3 * U(rng));
		FrameCloudBuilder b(p);
		FrameCloud f;
		b.build(*scan, T_WS, f);
		// Twice with the same builder and cloud (scratch reuse).
		if (trial % 4 == 0) b.build(*scan, T_WS, f);
		const Plain ref = plainBuild(*scan, T_WS, p);
		ASSERT_NO_FATAL_FAILURE(expectSameAsPlain(f, ref, p.voxel_size, trial));
		checked[0] += ref.st.valid;
		checked[1] += ref.st.beyondRange;
		checked[2] += ref.st.outsideExtent;
		checked[3] += ref.st.nonFinite;
		checked[4] += ref.st.noDepth;
		fast += kind == 0 || kind == 4 || kind == 5;
	}
	// Every reason occurred.
	for (size_t c : checked) EXPECT_GT(c, 100u);
	EXPECT_GT(fast, 0u);
}

// Frames whose bounding box holds too many blocks for a bucket per block
// (a few readings far apart), also with keys too wide to be packed with
// the run index in 64 bits.
TEST(FrameCloud, CellsOfSparseFramesSpanningManyBlocks)
{
	for (int wide = 0; wide < 2; ++wide)
	{
		GridParams p = test::paperGrids();
		p.voxel_size = wide ? 0.01 : 0.02;
		p.max_range = wide ? 5000 : 30;
		p.extent = wide ? 4000 : 500;
		const double span = wide ? 2800 : 17;
		std::mt19937 rng(5 + wide);
		std::uniform_real_distribution<double> U(-span, span);
		std::vector<mrpt::math::TPoint3Df> pts;
		for (int i = 0; i < 300; ++i)
		{
			const float x = float(U(rng)), y = float(U(rng)), z = float(U(rng));
			for (int j = 0; j < 1 + i % 3; ++j)  // runs and repeats
				pts.emplace_back(x + 0.001f * j, y, z);
			if (i % 7 == 0) pts.push_back(pts[size_t(i)]);
		}
		FrameCloudBuilder b(p);
		FrameCloud f;
		b.buildFromPoints(pts, {}, {0.1, 0.2, -0.3}, f);
		ASSERT_EQ(f.numPoints(), pts.size());
		expectCellsOfReadings(f, p.voxel_size);
	}
}

// VGA frames (the SSE2 pairs of the fast path, an odd width for the last
// pixel of a row, and many more runs than the cache of recent keys has
// slots, so that keys are evicted and come back as new entries), built one
// after the other with the same builder and cloud (their buffers grow and
// shrink between frames of more and fewer readings): each equals the plain
// per-pixel definition and a build with a fresh builder and cloud.
TEST(FrameCloud, VgaFramesWithReusedBuffersEqualThePlainDefinition)
{
	std::mt19937 rng(23);
	std::uniform_real_distribution<double> U(-1, 1);
	GridParams p = test::paperGrids();
	p.max_range = 6;
	FrameCloudBuilder b(p);
	FrameCloud f;
	for (int trial = 0; trial < 9; ++trial)
	{
		p.voxel_size = trial % 2 == 0 ? 0.02 : 0.05;
		b.setParams(p);
		const int W = trial == 3 || trial == 7 ? 639 : 640, H = 480;
		const bool isDepth = trial != 4;
		auto scan = randomScan(rng, W, H, 1.0f / 5000, isDepth, 65535);
		// Noisy depth (short runs), holes, saturated and far readings; the
		// share of holes changes from frame to frame.
		std::normal_distribution<double> noise(0, 0.01);
		const double holes = 0.02 + 0.1 * (trial % 3);
		std::uniform_real_distribution<double> P(0, 1);
		for (int v = 0; v < H; ++v)
			for (int u = 0; u < W; ++u)
			{
				const double q = P(rng);
				const double z =
				    1 + 3 * (0.5 + 0.5 * std::sin(u * 0.01 + v * 0.02)) +
				    noise(rng);
				scan->rangeImage(v, u) =
				    q < holes
				        ? 0
				        : (q < holes + 0.01
				               ? 65535
				               : uint16_t(std::clamp(z * 5000, 1.0, 65534.0)));
			}
		// Holes in runs (trials 6-8: the fast path skips 8 pixels without
		// depth at once): a thinned image (every 3rd pixel of every 3rd
		// row), then rectangles of no depth at odd places.
		if (trial == 6)
			for (int v = 0; v < H; ++v)
				for (int u = 0; u < W; ++u)
					if (u % 3 || v % 3) scan->rangeImage(v, u) = 0;
		if (trial >= 7)
			for (int k = 0; k < 40; ++k)
			{
				const int u0 = int(rng() % W), v0 = int(rng() % H);
				const int w = 1 + int(rng() % 90), h = 1 + int(rng() % 60);
				for (int v = v0; v < std::min(H, v0 + h); ++v)
					for (int u = u0; u < std::min(W, u0 + w); ++u)
						scan->rangeImage(v, u) = 0;
			}
		const mrpt::poses::CPose3D T_WS(3 * U(rng), 3 * U(rng), 3 * U(rng),
		                                3 * U(rng), 1.5 * U(rng), 3 * U(rng));
		b.build(*scan, T_WS, f);
		const Plain ref = plainBuild(*scan, T_WS, p);
		ASSERT_GT(ref.st.beyondRange, trial == 6 ? 100u : 1000u) << trial;
		ASSERT_NO_FATAL_FAILURE(expectSameAsPlain(f, ref, p.voxel_size, trial));
		FrameCloudBuilder fresh(p);
		FrameCloud g;
		fresh.build(*scan, T_WS, g);
		ASSERT_EQ(g.cells, f.cells) << trial;
		ASSERT_EQ(g.hits, f.hits) << trial;
		ASSERT_EQ(g.cellOfPoint, f.cellOfPoint) << trial;
	}
}
