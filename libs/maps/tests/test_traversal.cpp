// The fast paths of the grids against their plain definitions: a
// FrameCloud's cells are the distinct voxels of its readings in block order;
// the raycast decay equals a per-voxel DDA on a std::map.
#include <bims/maps/COccupancyBayesGrid.h>
#include <bims/maps/dda.h>
#include <bims/maps/frame_cloud.h>

#include <gtest/gtest.h>

#include "scene_raycaster.h"
#include "test_util.h"

#include <map>
#include <random>
#include <set>
#include <tuple>
#include <vector>

using namespace bims::maps;

TEST(FrameCloud, CellsAreTheDistinctVoxelsOfTheReadingsInBlockOrder)
{
	for (double voxel : {0.02, 0.05, 0.3})
	{
		GridParams p = test::paperGrids();
		p.voxel_size = voxel;
		p.max_range = 6;
		std::mt19937 rng(3);
		std::normal_distribution<float> N(0, 2);
		std::vector<mrpt::math::TPoint3Df> pts;
		for (int i = 0; i < 20000; ++i)
		{
			// Clustered readings (many per voxel), some beyond max_range.
			const float x = N(rng), y = N(rng), z = N(rng);
			for (int j = 0; j < 3; ++j)
				pts.emplace_back(x + 0.004f * j, y, z - 0.003f * j);
		}
		pts.emplace_back(NAN, 0.f, 0.f);
		const mrpt::math::TPoint3D origin(0.3, -0.2, 0.1);
		FrameCloudBuilder b(p);
		FrameCloud f;
		b.buildFromPoints(pts, {}, origin, f);
		ASSERT_EQ(f.stats.nonFinite, 1u);
		ASSERT_GT(f.stats.beyondRange, 0u);
		ASSERT_EQ(f.numPoints() + f.stats.skipped(), pts.size());
		// Reference: voxel of each kept reading, counted in a std::map.
		auto keyOf = [&](const mrpt::math::TPoint3Df& q)
		{
			const double inv = 1 / voxel;
			return VoxelKey{coordToIndex(q.x, inv), coordToIndex(q.y, inv),
			                coordToIndex(q.z, inv)};
		};
		auto order = [](const VoxelKey& k)
		{
			return std::make_tuple(k.x >> 3, k.y >> 3, k.z >> 3, k.z & 7,
			                       k.y & 7, k.x & 7);
		};
		std::map<decltype(order(VoxelKey())), uint32_t> ref;
		for (size_t i = 0; i < f.numPoints(); ++i)
		{
			const VoxelKey k = keyOf(f.points_W[i]);
			ref[order(k)]++;
			ASSERT_LT(f.cellOfPoint[i], f.numCells());
			ASSERT_EQ(f.cells[f.cellOfPoint[i]], k) << "reading " << i;
		}
		ASSERT_EQ(f.numCells(), ref.size());
		size_t c = 0;
		for (const auto& [o, n] : ref)
		{
			EXPECT_EQ(order(f.cells[c]), o) << "cell " << c;
			EXPECT_EQ(f.hits[c], n) << "cell " << c;
			++c;
		}
	}
}

// decay = raycast (ray ends in tile order, the per-frame block table, with
// 1 or 2 threads) against a plain per-voxel reference: a std::map updated
// along traverseRay() from the sensor origin to each reading.
TEST(Raycast, SameResultAsAPlainDdaOnAMapWithAnyThreadCount)
{
	auto scene = bims::maps::test::room();
	scene.push_back({{1.0, -0.6, 0}, {1.6, 0.4, 1.4}});
	const mrpt::poses::CPose3D poses[] = {{-1, 0.3, 1.2, 0.2, 0.1, 0},
	                                      {-0.5, -0.4, 1.0, -0.6, 0.0, 0.1},
	                                      {-1, 0.3, 1.2, 2.0, -0.2, 0}};
	GridParams p = test::paperGrids();
	p.decay = DecayMode::Raycast;
	p.raycast_margin = 0;  // the reference walks to the readings
	p.voxel_size = 0.04;
	COccupancyBayesGrid g1(p);
	p.raycast_threads = 2;
	COccupancyBayesGrid g2(p);
	FrameCloudBuilder b(p);
	std::map<std::tuple<int, int, int>, LogOddsFx> ref;
	for (int f = 0; f < 3; ++f)
	{
		const auto scan =
		    bims::maps::test::renderScan(scene, poses[f], 100, 75, 70, f);
		FrameCloud fc;
		b.build(*scan, poses[f], fc);
		ASSERT_GT(fc.numPoints(), 5000u);  // > 2 work items of rays
		g1.integrate(fc);
		g2.integrate(fc);
		// Reference: hits first, then one miss per voxel crossed.
		std::set<std::tuple<int, int, int>> touched;
		for (size_t i = 0; i < fc.numCells(); ++i)
		{
			const auto& k = fc.cells[i];
			auto& l = ref[{k.x, k.y, k.z}];
			l = LogOddsFx(std::min<int64_t>(
			    int64_t(l) + g1.hitFixed(fc.hits[i]), g1.maxFixed()));
			touched.insert({k.x, k.y, k.z});
		}
		const double inv = 1 / p.voxel_size;
		const double a[3] = {fc.origin_W.x * inv, fc.origin_W.y * inv,
		                     fc.origin_W.z * inv};
		for (const auto& q : fc.points_W)
		{
			const double e[3] = {q.x * inv, q.y * inv, q.z * inv};
			traverseRay(a, e,
			            [&](int32_t x, int32_t y, int32_t z)
			            {
				            if (!touched.insert({x, y, z}).second) return;
				            auto& l = ref[{x, y, z}];
				            l = std::max<LogOddsFx>(l - g1.missFixed(),
				                                    g1.minFixed());
			            });
		}
	}
	size_t compared = 0;
	for (const auto& [k, l] : ref)
	{
		const VoxelKey key{std::get<0>(k), std::get<1>(k), std::get<2>(k)};
		ASSERT_EQ(g1.logOddsFixed(key), l);
		ASSERT_EQ(g2.logOddsFixed(key), l);
		++compared;
	}
	// Nothing else was touched: as many stored cells with a stamp.
	for (const auto* g : {&g1, &g2})
	{
		size_t stamped = 0;
		g->storage().forEachCell([&](const VoxelKey&, const auto& c)
		                         { stamped += c.stamp != 0; });
		EXPECT_EQ(stamped, compared);
	}
	EXPECT_GT(compared, 20000u);
}

// decay = frustum (boxes of cells decided at once where the rule provably
// gives one answer) against the plain rule applied to every stored cell:
// hits first, then each stored cell not hit whose centre projects onto a
// measured depth d with z + half diagonal < d gets one miss. Random rooms
// with boxes that come and go (cells in front of the depth, behind it, out
// of view, behind the camera), depth holes, several voxel sizes.
TEST(Frustum, SameResultAsThePlainRuleOnEveryStoredCell)
{
	using bims::maps::test::Box;
	std::mt19937 rng(7);
	std::uniform_real_distribution<double> U(-1, 1);
	size_t decayed = 0, kept = 0;
	for (double voxel : {0.03, 0.05, 0.1})
	{
		GridParams p = test::paperGrids();
		p.decay = DecayMode::Frustum;
		p.voxel_size = voxel;
		p.max_range = 7;
		COccupancyBayesGrid g(p);
		FrameCloudBuilder b(p);
		using Cell = COccupancyBayesGrid::Cell;
		std::map<std::tuple<int, int, int>, Cell> ref;
		const auto room = bims::maps::test::room();
		for (int fr = 1; fr <= 8; ++fr)
		{
			auto scene = room;
			// Boxes that exist in some frames only.
			std::mt19937 boxes(uint32_t(fr / 3));
			std::uniform_real_distribution<double> B(-3, 3);
			for (int i = 0; i < 6; ++i)
			{
				const double x = B(boxes), y = B(boxes), z = 1.5 + B(boxes) / 3;
				scene.push_back({{x, y, z - 0.3}, {x + 0.4, y + 0.5, z + 0.3}});
			}
			const mrpt::poses::CPose3D T_WS(2 * U(rng), 2 * U(rng),
			                                1.5 + 0.5 * U(rng), 3.2 * U(rng),
			                                0.5 * U(rng), 0.3 * U(rng));
			const auto scan =
			    bims::maps::test::renderScan(scene, T_WS, 80, 60, 70, fr);
			// Holes in the depth image.
			for (int v = 0; v < 60; ++v)
				for (int u = 0; u < 80; ++u)
					if (rng() % 17 == 0) scan->rangeImage(v, u) = 0;
			FrameCloud f;
			b.build(*scan, T_WS, f);
			ASSERT_GT(f.numPoints(), 1000u);
			g.integrate(f);
			const uint32_t F = uint32_t(fr);
			// Reference: the hits (their blocks are stored whole).
			for (size_t i = 0; i < f.numCells(); ++i)
			{
				const VoxelKey& k = f.cells[i];
				const int bx = k.x >> 3, by = k.y >> 3, bz = k.z >> 3;
				if (!ref.count({bx * 8, by * 8, bz * 8}))
					for (int z = 0; z < 8; ++z)
						for (int y = 0; y < 8; ++y)
							for (int x = 0; x < 8; ++x)
								ref[{bx * 8 + x, by * 8 + y, bz * 8 + z}] =
								    Cell();
				Cell& c = ref[{k.x, k.y, k.z}];
				c.lPrev = c.l;
				c.l = LogOddsFx(std::min<int64_t>(
				    int64_t(c.l) + g.hitFixed(f.hits[i]), g.maxFixed()));
				c.stamp = F;
			}
			// Reference: the plain rule on every stored cell.
			const auto& R = f.T_WC.getRotationMatrix();
			const auto t = f.T_WC.translation();
			const auto& K = f.K;
			for (auto& [key, c] : ref)
			{
				if (c.stamp == F) continue;
				const double x = (std::get<0>(key) + 0.5) * voxel - t.x,
				             y = (std::get<1>(key) + 0.5) * voxel - t.y,
				             z = (std::get<2>(key) + 0.5) * voxel - t.z;
				double pc[3];
				for (int r = 0; r < 3; ++r)
					pc[r] = R(0, r) * x + R(1, r) * y + R(2, r) * z;
				if (pc[2] <= 1e-6) continue;
				const long u = std::lround(K.fx * pc[0] / pc[2] + K.cx),
				           v = std::lround(K.fy * pc[1] / pc[2] + K.cy);
				if (u < 0 || v < 0 || u >= K.width || v >= K.height) continue;
				const float d = f.depth[size_t(v) * K.width + size_t(u)];
				if (d > 0 && pc[2] + voxel * std::sqrt(3.0) / 2 < d)
				{
					c.lPrev = c.l;
					c.l =
					    std::max<LogOddsFx>(c.l - g.missFixed(), g.minFixed());
					c.stamp = F;
					++decayed;
				}
				else
					++kept;
			}
			// Every stored cell equals the reference, and nothing else is
			// stored.
			size_t stored = 0;
			g.storage().forEachCell(
			    [&](const VoxelKey& k, const Cell& c)
			    {
				    ++stored;
				    auto it = ref.find({k.x, k.y, k.z});
				    ASSERT_TRUE(it != ref.end());
				    ASSERT_EQ(c.l, it->second.l) << "frame " << fr;
				    ASSERT_EQ(c.lPrev, it->second.lPrev) << "frame " << fr;
				    ASSERT_EQ(c.stamp, it->second.stamp) << "frame " << fr;
			    });
			ASSERT_EQ(stored, ref.size());
		}
	}
	EXPECT_GT(decayed, 10000u);
	EXPECT_GT(kept, 10000u);
}

// beginFrame() + integratePending() (one storage lookup per voxel for O-
// and the update) against priorLogOdds() + integrate(): the same O-, the
// same cells, also for a repeated timestamp, held voxels, p_unknown and a
// memory budget that stops block creation; a changed map in between is an
// error.
TEST(OccupancyGrid, BeginFrameThenIntegratePendingEqualsPriorThenIntegrate)
{
	for (int variant = 0; variant < 3; ++variant)
	{
		GridParams p = test::paperGrids();
		p.voxel_size = 0.05;
		p.reading_lambda = 1.5;
		if (variant == 1) p.p_unknown = 0.9;
		if (variant == 2) p.max_memory_mb = 1;  // ~170 blocks of 6 KiB
		COccupancyBayesGrid a(p), b(p);
		FrameCloudBuilder fb(p);
		std::mt19937 rng(21 + variant);
		std::normal_distribution<float> N(0, 1.5f);
		size_t over = 0;
		for (int fr = 0; fr < 12; ++fr)
		{
			std::vector<mrpt::math::TPoint3Df> pts;
			for (int i = 0; i < 3000; ++i)
				pts.emplace_back(N(rng), N(rng), N(rng));
			FrameCloud f;
			fb.buildFromPoints(pts, {}, {0, 0, 0}, f);
			// Frames 4 and 5 share a timestamp (the second is "already
			// integrated" for priorLogOdds()).
			f.timestamp = mrpt::Clock::time_point(
			    mrpt::Clock::duration(fr == 5 ? 4 : fr));
			std::vector<uint8_t> hold(f.numCells());
			for (auto& h : hold) h = rng() % 4 == 0;
			std::vector<float> pa, pb;
			a.priorLogOdds(f, pa);
			a.integrate(f, nullptr, &hold);
			b.beginFrame(f, pb);
			b.integratePending(f, &hold);
			ASSERT_EQ(pa.size(), pb.size());
			for (size_t i = 0; i < pa.size(); ++i)
				ASSERT_EQ(pa[i], pb[i]) << "frame " << fr << " cell " << i;
			over = a.totalStats().overBudget;
			ASSERT_EQ(a.totalStats().overBudget, b.totalStats().overBudget);
		}
		ASSERT_EQ(a.storage().numBlocks(), b.storage().numBlocks());
		for (size_t k = 0; k < a.storage().numBlocks(); ++k)
		{
			ASSERT_EQ(a.storage().blockKey(k), b.storage().blockKey(k));
			for (size_t c = 0; c < COccupancyBayesGrid::Storage::kCellsPerBlock;
			     ++c)
			{
				const auto& x = a.storage().block(k).cells[c];
				const auto& y = b.storage().block(k).cells[c];
				ASSERT_EQ(x.l, y.l);
				ASSERT_EQ(x.lPrev, y.lPrev);
				ASSERT_EQ(x.stamp, y.stamp);
			}
		}
		if (variant == 2)
		{
			EXPECT_GT(over, 0u);
		}
		// A map updated between the halves.
		FrameCloud f;
		fb.buildFromPoints({{0.1f, 0.2f, 0.3f}}, {}, {0, 0, 0}, f);
		std::vector<float> pr;
		b.beginFrame(f, pr);
		b.integrate(f);
		EXPECT_THROW(b.integratePending(f, nullptr), std::logic_error);
	}
}

// decay = raycast against the per-cell walk it replaced: the same rays (in
// the order of the frame's readings, as decayRaycast() casts an unorganised
// frame) walked with traverseRay() through a cached-block accessor on a
// second storage. Compared bit for bit: every cell (log-odds, O-, stamp),
// the blocks and their creation order, the readings over the memory budget.
// Random clouds and origins (also inside blocks of negative coordinates),
// rays along the axes, end points and origins on block corners, rays of
// thousands of voxels, p_unknown, and a memory budget that runs out.
TEST(Raycast, SameCellsBlocksAndOrderAsThePerCellWalk)
{
	using Cell = COccupancyBayesGrid::Cell;
	struct Case
	{
		double voxel, p_unknown, mb;
		int kind;  // 0 random, 1 axes and corners, 2 long rays in a cone
	};
	const Case cases[] = {{0.05, 0, 4096, 0}, {0.02, 0.3, 4096, 0},
	                      {0.25, 0, 4096, 1}, {0.125, 0.6, 4096, 1},
	                      {0.02, 0, 4096, 2}, {0.05, 0, 1, 0},
	                      {0.02, 0.3, 1.5, 2}};
	std::mt19937 rng(11);
	for (const auto& cs : cases)
	{
		SCOPED_TRACE("voxel " + std::to_string(cs.voxel) + " kind " +
		             std::to_string(cs.kind) + " mb " + std::to_string(cs.mb));
		GridParams p = test::paperGrids();
		p.decay = DecayMode::Raycast;
		p.raycast_margin = 0;  // the reference walks to the readings
		p.voxel_size = cs.voxel;
		p.p_unknown = cs.p_unknown;
		p.max_memory_mb = cs.mb;
		p.max_range = cs.kind == 2 ? 90 : 12;
		p.extent = 200;
		COccupancyBayesGrid g(p);
		const LogOddsFx unknown = g.logOddsFixed(VoxelKey{-9999, 0, 0});
		SparseVoxelGrid<Cell, 3> ref(size_t(cs.mb * 1048576.0));
		size_t refOver = 0;
		FrameCloudBuilder b(p);
		std::uniform_real_distribution<double> U(-1, 1);
		for (int frame = 1; frame <= 4; ++frame)
		{
			const uint32_t F = uint32_t(frame);
			// Origin: random, also in negative blocks; on a block corner
			// for the axis/corner clouds.
			const double s = cs.voxel;
			mrpt::math::TPoint3D o(U(rng) * 3, U(rng) * 3 - 1.5, U(rng) * 2);
			if (cs.kind == 1)
				o = {-8 * s * (frame % 3), 8 * s * (frame - 2), -16 * s};
			std::vector<mrpt::math::TPoint3Df> pts;
			if (cs.kind == 0)
				for (int i = 0; i < 4000; ++i)
					pts.emplace_back(float(o.x + U(rng) * 6),
					                 float(o.y + U(rng) * 6),
					                 float(o.z + U(rng) * 4));
			else if (cs.kind == 1)
			{
				// Along each axis (both senses), through block corners and
				// edges, ending on corners.
				for (int k = 1; k <= 40; ++k)
					for (int ax = 0; ax < 3; ++ax)
						for (int sg : {-1, 1})
						{
							double q[3] = {o.x, o.y, o.z};
							q[ax] += sg * k * s;
							pts.emplace_back(float(q[0]), float(q[1]),
							                 float(q[2]));
						}
				for (int i = -6; i <= 6; ++i)
					for (int j = -6; j <= 6; ++j)
					{
						pts.emplace_back(float(o.x + 8 * s * i),
						                 float(o.y + 8 * s * j),
						                 float(o.z + 8 * s * 3));
						pts.emplace_back(float(o.x + 8 * s * i),
						                 float(o.y + 8 * s * i),
						                 float(o.z + 8 * s * j));
						pts.emplace_back(float(o.x + s * (4 * i + 0.5)),
						                 float(o.y + 8 * s * j), float(o.z));
					}
			}
			else
				for (int i = 0; i < 600; ++i)
					pts.emplace_back(float(o.x + 40 + U(rng) * 30),
					                 float(o.y + U(rng) * 3),
					                 float(o.z + U(rng) * 3));
			FrameCloud fc;
			b.buildFromPoints(pts, {}, o, fc);
			ASSERT_GT(fc.numPoints(), 100u);
			g.integrate(fc);
			// Reference: the hits, then the rays cell by cell.
			std::vector<Cell*> hit;
			ref.resolve(fc.cells, hit);
			for (size_t i = 0; i < fc.numCells(); ++i)
			{
				if (!hit[i])
				{
					refOver += fc.hits[i];
					continue;
				}
				Cell& c = *hit[i];
				const LogOddsFx prior =
				    (c.stamp == 0 && cs.p_unknown > 0) ? unknown : c.l;
				c.lPrev = prior;
				c.l = LogOddsFx(std::min<int64_t>(
				    int64_t(prior) + g.hitFixed(fc.hits[i]), g.maxFixed()));
				c.stamp = F;
			}
			SparseVoxelGrid<Cell, 3>::Accessor acc(ref);
			const double inv = 1 / s;
			const double a[3] = {fc.origin_W.x * inv, fc.origin_W.y * inv,
			                     fc.origin_W.z * inv};
			for (const auto& q : fc.points_W)
			{
				const double e[3] = {q.x * inv, q.y * inv, q.z * inv};
				traverseRay(a, e,
				            [&](int32_t x, int32_t y, int32_t z)
				            {
					            Cell* c = acc.get(x, y, z);
					            if (!c)
					            {
						            ++refOver;
						            return;
					            }
					            if (c->stamp == F) return;
					            if (c->stamp == 0 && cs.p_unknown > 0)
						            c->l = unknown;
					            c->lPrev = c->l;
					            c->l = std::max<LogOddsFx>(c->l - g.missFixed(),
					                                       g.minFixed());
					            c->stamp = F;
				            });
			}
			const auto& st = g.storage();
			ASSERT_EQ(st.numBlocks(), ref.numBlocks()) << "frame " << frame;
			for (size_t i = 0; i < st.numBlocks(); ++i)
			{
				ASSERT_EQ(st.blockKey(i), ref.blockKey(i)) << "block " << i;
				for (size_t c = 0; c < SparseVoxelGrid<Cell, 3>::kCellsPerBlock;
				     ++c)
				{
					const Cell &u = st.block(i).cells[c],
					           &v = ref.block(i).cells[c];
					ASSERT_TRUE(u.l == v.l && u.lPrev == v.lPrev &&
					            u.stamp == v.stamp)
					    << "block " << i << " cell " << c << " frame " << frame;
				}
			}
			ASSERT_EQ(g.totalStats().overBudget, refOver) << "frame " << frame;
			if (cs.mb < 100 && frame == 4)
			{
				EXPECT_GT(refOver, 0u);
			}
		}
	}
}
