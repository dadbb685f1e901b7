// decay = raycast, the marked walk (ray_marks.h) against its plain
// definition: traverseRay() ray after ray, step after step. The marks
// (crossed voxels, the earliest visit of each block not stored) of random
// rays split over any number of parts, and the map after whole frames of
// the Bonn recording, voxel for voxel, with 1 and 2 threads.
#include <bims/eval/tum_import.h>
#include <bims/maps/COccupancyBayesGrid.h>
#include <bims/maps/dda.h>
#include <bims/maps/frame_cloud.h>
#include <bims/maps/ray_marks.h>
#include <bims_test/data.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <set>
#include <tuple>
#include <vector>

using namespace bims::maps;

namespace
{
using Key = std::tuple<int32_t, int32_t, int32_t>;

/** Blocks stored for the walk: those in a std::set. */
// Every walker this CPU runs (the others are skipped).
constexpr RayLanes kLanes[] = {RayLanes::One, RayLanes::Four, RayLanes::Eight};

bool inSet(const void* ctx, int32_t bx, int32_t by, int32_t bz)
{
	return static_cast<const std::set<Key>*>(ctx)->count({bx, by, bz}) > 0;
}

/** The rays of decayRaycast() for \a fc, in voxel units, in its order: one
 * per reading (by 8x8-pixel tile of the image, in reading order inside a
 * tile) or one per hit voxel, to its centre. */
std::vector<RayEnd> plainRayEnds(const FrameCloud& fc, RayTarget target,
                                 double margin = 0)
{
	std::vector<RayEnd> ends;
	const double inv = 1 / fc.voxel_size;
	// raycast_margin: the end moved towards the origin by the margin, the
	// ray dropped if not longer (in voxel units, the cast's arithmetic: the
	// walks are compared voxel for voxel).
	const mrpt::math::TPoint3D o = fc.origin_W * inv;
	const double m = margin * inv;
	auto add = [&](double x, double y, double z)
	{
		if (m <= 0)
		{
			ends.push_back({{x, y, z}});
			return;
		}
		const double d[3] = {x - o.x, y - o.y, z - o.z};
		const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
		if (n <= m) return;
		const double k = (n - m) / n;
		ends.push_back({{o.x + k * d[0], o.y + k * d[1], o.z + k * d[2]}});
	};
	if (target == RayTarget::Voxels)
	{
		for (const auto& k : fc.cells) add(k.x + 0.5, k.y + 0.5, k.z + 0.5);
		return ends;
	}
	const uint32_t W = uint32_t(fc.K.width), tw = (W + 7) / 8;
	std::vector<size_t> order(fc.numPoints());
	for (size_t i = 0; i < order.size(); ++i) order[i] = i;
	auto tile = [&](size_t i)
	{ return (fc.pixel[i] / W / 8) * tw + (fc.pixel[i] % W) / 8; };
	std::stable_sort(order.begin(), order.end(),
	                 [&](size_t i, size_t j) { return tile(i) < tile(j); });
	for (size_t i : order)
	{
		const auto& q = fc.points_W[i];
		add(q.x * inv, q.y * inv, q.z * inv);
	}
	return ends;
}

/** The plain ray cast of one frame on a second storage: the hits, then
 * each ray voxel by voxel through a cached-block accessor (blocks created
 * as the rays enter them), one miss per voxel not stamped with F. Returns
 * the steps into blocks over the memory budget. */
size_t plainFrame(SparseVoxelGrid<COccupancyBayesGrid::Cell, 3>& ref,
                  const FrameCloud& fc, const std::vector<RayEnd>& ends,
                  const COccupancyBayesGrid& g, uint32_t F, bool hasUnknown,
                  LogOddsFx unknown)
{
	using Cell = COccupancyBayesGrid::Cell;
	size_t over = 0;
	std::vector<Cell*> hit;
	ref.resolve(fc.cells, hit);
	for (size_t i = 0; i < fc.numCells(); ++i)
	{
		if (!hit[i])
		{
			over += fc.hits[i];
			continue;
		}
		Cell& c = *hit[i];
		const LogOddsFx prior = (c.stamp == 0 && hasUnknown) ? unknown : c.l;
		c.lPrev = prior;
		c.l = LogOddsFx(std::min<int64_t>(
		    int64_t(prior) + g.hitFixed(fc.hits[i]), g.maxFixed()));
		c.stamp = F;
	}
	SparseVoxelGrid<Cell, 3>::Accessor acc(ref);
	const double inv = 1 / fc.voxel_size;
	const double a[3] = {fc.origin_W.x * inv, fc.origin_W.y * inv,
	                     fc.origin_W.z * inv};
	for (const auto& e : ends)
	{
		traverseRay(a, e.p,
		            [&](int32_t x, int32_t y, int32_t z)
		            {
			            Cell* c = acc.get(x, y, z);
			            if (!c)
			            {
				            ++over;
				            return;
			            }
			            if (c->stamp == F) return;
			            if (c->stamp == 0 && hasUnknown) c->l = unknown;
			            c->lPrev = c->l;
			            c->l = std::max<LogOddsFx>(c->l - g.missFixed(),
			                                       g.minFixed());
			            c->stamp = F;
		            });
	}
	return over;
}

/** Every cell and block (in order) of \a g equals \a ref. */
void expectSameStorage(const COccupancyBayesGrid& g,
                       const SparseVoxelGrid<COccupancyBayesGrid::Cell, 3>& ref)
{
	const auto& st = g.storage();
	ASSERT_EQ(st.numBlocks(), ref.numBlocks());
	for (size_t i = 0; i < st.numBlocks(); ++i)
	{
		ASSERT_EQ(st.blockKey(i), ref.blockKey(i)) << "block " << i;
		for (size_t c = 0; c < COccupancyBayesGrid::Storage::kCellsPerBlock;
		     ++c)
		{
			const auto &u = st.block(i).cells[c], &v = ref.block(i).cells[c];
			ASSERT_TRUE(u.l == v.l && u.lPrev == v.lPrev && u.stamp == v.stamp)
			    << "block " << i << " cell " << c;
		}
	}
}
}  // namespace

// markRays() against traverseRay(): the crossed bits are exactly the voxels
// the rays visit, and the earliest visit (ray, step) of each block not
// stored is the plain walk's, whether the rays are walked in one part or
// split into parts merged afterwards (as threads do), with odd and even
// counts of rays (the two-lane walk runs a lone last ray in both lanes).
TEST(RayMarks, SameVoxelsAndFirstVisitsAsTraverseRay)
{
	std::mt19937 rng(5);
	std::uniform_real_distribution<double> U(-1, 1);
	// Reused over the trials and lanes, as the grid reuses them over frames
	// (reset() clears only what the last walk marked).
	std::vector<RayMarks> marks(3);
	for (int trial = 0; trial < 12; ++trial)
	{
		const double a[3] = {U(rng) * 20, U(rng) * 20 - 30, U(rng) * 20};
		std::vector<RayEnd> ends;
		const size_t count = 1 + rng() % 700;
		const double len = trial % 3 == 0 ? 4 : 60;
		for (size_t i = 0; i < count; ++i)
		{
			RayEnd e{{a[0] + U(rng) * len, a[1] + U(rng) * len,
			          a[2] + U(rng) * len}};
			if (i % 7 == 0) e.p[1] = a[1];  // in a plane of the axes
			if (i % 11 == 0) e.p[0] = std::floor(e.p[0]);  // on a boundary
			ends.push_back(e);
		}
		// Reference: the voxels and per block the earliest (ray, step).
		std::set<Key> voxels;
		std::map<Key, uint64_t> first;
		int32_t lo[3], hi[3];
		for (int k = 0; k < 3; ++k) lo[k] = hi[k] = int32_t(std::floor(a[k]));
		for (size_t r = 0; r < ends.size(); ++r)
		{
			uint32_t step = 0;
			traverseRay(a, ends[r].p,
			            [&](int32_t x, int32_t y, int32_t z)
			            {
				            voxels.insert({x, y, z});
				            first.emplace(Key{x >> 3, y >> 3, z >> 3},
				                          (uint64_t(r) << 32) | step++);
				            const int32_t v[3] = {x, y, z};
				            for (int k = 0; k < 3; ++k)
					            lo[k] = std::min(lo[k], v[k]),
					            hi[k] = std::max(hi[k], v[k]);
			            });
		}
		for (int k = 0; k < 3; ++k)
			lo[k] = (lo[k] >> 3) - 1, hi[k] = (hi[k] >> 3) + 1;
		const RayBox box(lo, hi);
		// Every third block visited is stored.
		std::set<Key> stored;
		size_t i = 0;
		for (const auto& [b, v] : first)
			if (i++ % 3 == 0) stored.insert(b);
		for (const RayLanes lanes : kLanes)
			for (size_t parts : {size_t(1), size_t(3)})
			{
				if (!rayLanesSupported(lanes)) continue;
				for (size_t p = 0; p < parts; ++p)
				{
					marks[p].reset(box);
					// Part p takes every parts-th run of 50 rays.
					for (size_t r0 = 50 * p; r0 < ends.size(); r0 += 50 * parts)
						markRays(a, ends.data(), r0,
						         std::min(ends.size(), r0 + 50), box, inSet,
						         &stored, marks[p], lanes);
				}
				for (size_t p = 1; p < parts; ++p)
					mergeRayMarks(marks[0], marks[p]);
				const RayMarks& m = marks[0];
				const std::string at = "trial " + std::to_string(trial) +
				                       " lanes " + std::to_string(int(lanes));
				size_t crossed = 0;
				for (const uint64_t w : m.bits)
					crossed += size_t(__builtin_popcountll(w));
				ASSERT_EQ(crossed, voxels.size()) << at;
				for (const auto& [x, y, z] : voxels)
				{
					const uint64_t g = box.bitOf(x, y, z);
					ASSERT_TRUE((m.bits[g >> 6] >> (g & 63)) & 1) << at;
				}
				ASSERT_EQ(m.touched.size(), first.size()) << at;
				for (const auto& [b, v] : first)
				{
					const auto& [bx, by, bz] = b;
					const size_t bi = box.blockOf(bx, by, bz);
					int32_t c[3];
					box.blockCoords(bi, c);
					ASSERT_TRUE(c[0] == bx && c[1] == by && c[2] == bz) << at;
					const bool isStored = stored.count(b) > 0;
					ASSERT_EQ(m.stored(bi), isStored) << at;
					ASSERT_EQ(m.missing(bi), !isStored) << at;
					if (!isStored)
					{
						ASSERT_EQ(m.firstVisit[bi], v) << at;
					}
				}
			}
	}
}

// The map after frames of the Bonn recording (VGA, 265 986 readings in its
// first frame) with decay = raycast equals the plain walk voxel for voxel:
// every cell, the blocks in their order, the over-budget counts; frames
// from three poses (blocks stored, missing, both), one ray per reading and
// per hit voxel, 1 and 2 threads, and a memory budget that runs out.
TEST(Raycast, BonnFramesEqualThePlainWalkVoxelForVoxel)
{
	const std::string dir = bims::test::kBonnCrowd + "/depth";
	if (!std::filesystem::is_directory(dir))
		GTEST_SKIP() << "shared data missing: " << dir;
	std::vector<std::string> pngs;
	for (const auto& e : std::filesystem::directory_iterator(dir))
		if (e.path().extension() == ".png") pngs.push_back(e.path().string());
	std::sort(pngs.begin(), pngs.end());
	ASSERT_GE(pngs.size(), 3u);
	// config/bonn.ini's camera; range units of the PNG's, its values kept
	bims::eval::ImportParams bonn;
	bonn.loadFromConfigFile(mrpt::config::CConfigFile(
	    std::string(BIMS_SOURCE_DIR) + "/config/bonn.ini"));
	bonn.rangeUnits = 1.0 / bonn.camera.depthScale;
	auto scanOf = [&bonn](const std::string& path)
	{ return bims::eval::loadDepthFrame(path, 0, bonn); };
	const mrpt::poses::CPose3D poses[] = {{0, 0, 1.5, 0, 0, 0},
	                                      {0.3, -0.2, 1.4, 0.2, 0.05, 0},
	                                      {0.1, 0.4, 1.6, -0.3, 0, 0.1}};
	struct Case
	{
		double voxel;
		RayTarget target;
		int threads;
		double mb;
		double margin;
	};
	const Case cases[] = {{0.05, RayTarget::Points, 1, 4096, 0},
	                      {0.05, RayTarget::Points, 2, 4096, 0.1},
	                      {0.02, RayTarget::Points, 2, 4096, 0},
	                      {0.02, RayTarget::Voxels, 1, 4096, 0},
	                      {0.05, RayTarget::Voxels, 2, 4096, 0.1},
	                      {0.05, RayTarget::Points, 2, 1.5, 0.07}};
	for (const auto& cs : cases)
	{
		SCOPED_TRACE("voxel " + std::to_string(cs.voxel) + " threads " +
		             std::to_string(cs.threads) + " mb " +
		             std::to_string(cs.mb) + " margin " +
		             std::to_string(cs.margin));
		GridParams p;
		p.decay = DecayMode::Raycast;
		p.raycast_margin = cs.margin;
		p.voxel_size = cs.voxel;
		p.raycast_target = cs.target;
		p.raycast_threads = cs.threads;
		p.max_memory_mb = cs.mb;
		p.p_unknown = 0.6;
		COccupancyBayesGrid g(p);
		const LogOddsFx unknown = g.logOddsFixed(VoxelKey{-9999, 0, 0});
		SparseVoxelGrid<COccupancyBayesGrid::Cell, 3> ref(
		    size_t(cs.mb * 1048576.0));
		size_t refOver = 0;
		FrameCloudBuilder b(p);
		for (int fr = 0; fr < 3; ++fr)
		{
			FrameCloud fc;
			b.build(*scanOf(pngs[size_t(fr)]), poses[fr], fc);
			ASSERT_GT(fc.numPoints(), 200000u);
			g.integrate(fc);
			refOver +=
			    plainFrame(ref, fc, plainRayEnds(fc, cs.target, cs.margin), g,
			               uint32_t(fr + 1), true, unknown);
			expectSameStorage(g, ref);
			ASSERT_EQ(g.totalStats().overBudget, refOver) << "frame " << fr;
		}
		if (cs.mb < 100)
		{
			EXPECT_GT(refOver, 0u);
		}
	}
}
