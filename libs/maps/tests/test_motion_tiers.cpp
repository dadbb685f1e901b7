// Tiers 1 and 2 in the grids: closed forms applied with the right O-, order
// independence of a linked tier-0 map, MotionGrids == individual maps, and
// its fused passes (storePair, integrate) == the separate ones.
#include <bims/maps/closed_form.h>
#include <bims/maps/motion_grids.h>

#include <gtest/gtest.h>

#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>
#include <cmath>
#include <random>
#include <utility>

#include "scene_raycaster.h"
#include "test_util.h"

using namespace bims::maps;
using bims::maps::test::frameAt;

TEST(BackgroundGrid, PosteriorUsesOccupancyBeforeThisFrame)
{
	GridParams p = test::paperGrids();
	MotionGrids mg(p);
	const VoxelKey k{1, 2, 3};
	std::vector<double> expected;
	double lOcc = 0;
	for (int f = 1; f <= 4; ++f)
	{
		const auto fr = frameAt(p, {k}, {2}, {0, 0, 0}, f);
		mg.processFrame(fr, nullptr);
		const double want = backgroundPosterior(
		    lOcc, p.bg_transition_eps, p.p_miss, std::log(p.reading_lambda), 2);
		ASSERT_EQ(mg.background()->lastPosterior().size(), 1u);
		EXPECT_NEAR(mg.background()->lastPosterior()[0], want, 1e-5) << f;
		lOcc = fromFixed(mg.occupancy()->logOddsFixed(k));
	}
	// A voxel hit in every frame becomes background after a few frames.
	EXPECT_LT(mg.background()->lastPosterior()[0], 0);
	EXPECT_FALSE(mg.background()->wasMovingAtLastHit(k));
}

TEST(BackgroundGrid, LinkedTier0OrderDoesNotMatter)
{
	GridParams p = test::paperGrids();
	auto t0a = std::make_shared<COccupancyBayesGrid>(p);
	auto t0b = std::make_shared<COccupancyBayesGrid>(p);
	CBackgroundSubtractionGrid before(p), after(p);
	before.linkOccupancy(t0a);
	after.linkOccupancy(t0b);
	using namespace bims::maps::test;
	const auto scene = room();
	for (int f = 0; f < 4; ++f)
	{
		const mrpt::poses::CPose3D T(0.1 * f, 0, 1, 0.05 * f, 0, 0);
		auto scan = renderScan(scene, T, 40, 30, 60, f);
		before.insertObservation(*scan, T);  // tier 1 first
		t0a->insertObservation(*scan, T);
		t0b->insertObservation(*scan, T);  // tier 0 first
		after.insertObservation(*scan, T);
		ASSERT_EQ(before.lastPosterior(), after.lastPosterior()) << f;
		ASSERT_EQ(before.lastMovingMask().data, after.lastMovingMask().data);
	}
}

TEST(MotionGrids, SameResultAsIndividualMapsThroughInsertObservation)
{
	GridParams p = test::paperGrids();
	MotionGrids mg(p);
	CBackgroundSubtractionGrid t1(p);  // private tier-0 map
	CFlowConsistencyGrid t2(p);
	using namespace bims::maps::test;
	auto scene = room();
	for (int f = 0; f < 5; ++f)
	{
		scene.push_back({{2.0, -1.0 + 0.2 * f, 0}, {2.3, -0.7 + 0.2 * f, 1.5}});
		const mrpt::poses::CPose3D T(0, 0, 1, 0, 0, 0);
		auto scan = renderScan(scene, T, 64, 48, 60, f);
		PixelLabels labels(64, 48, 0);
		for (size_t i = 0; i < labels.label.size(); i += 3) labels.label[i] = 1;
		const auto& res = mg.processFrame(*scan, T, &labels);
		t1.insertObservation(*scan, T);
		t2.setPendingLabels(labels);
		t2.insertObservation(*scan, T);
		ASSERT_EQ(res.maskTier1().data, t1.lastMovingMask().data);
		ASSERT_EQ(res.maskTier2().data, t2.lastMovingMask().data);
		ASSERT_EQ(mg.flowConsistency()->lastPosterior(), t2.lastPosterior());
		ASSERT_EQ(mg.background()->lastCells(), t1.lastCells());
		ASSERT_EQ(mg.flowConsistency()->lastCells(), t2.lastCells());
		scene.pop_back();
	}
}

// MotionGrids hands tiers 1 and 2 the frame's cells (shared) and reuses its
// buffers: a copy of a map taken in between keeps its own last frame, and
// the maps keep theirs after the next frames.
TEST(MotionGrids, SharedCellsOfTheLastFrameAreNeverOverwritten)
{
	GridParams p = test::paperGrids();
	MotionGrids mg(p);
	using namespace bims::maps::test;
	const auto scene = room();
	std::vector<CBackgroundSubtractionGrid> copies;
	std::vector<std::vector<VoxelKey>> cellsSeen;
	std::vector<std::vector<float>> postSeen;
	for (int f = 0; f < 5; ++f)
	{
		const mrpt::poses::CPose3D T(0.1 * f, 0.05 * f, 1, 0.1 * f, 0, 0);
		auto scan = renderScan(scene, T, 40, 30, 60, f);
		mg.processFrame(*scan, T, nullptr);
		ASSERT_EQ(mg.background()->lastCells(), mg.lastFrame().cells);
		ASSERT_EQ(mg.flowConsistency()->lastCells(), mg.lastFrame().cells);
		copies.push_back(*mg.background());
		cellsSeen.push_back(mg.lastFrame().cells);
		postSeen.push_back(mg.background()->lastPosterior());
	}
	for (size_t i = 0; i < copies.size(); ++i)
	{
		ASSERT_EQ(copies[i].lastCells(), cellsSeen[i]) << i;
		ASSERT_EQ(copies[i].lastPosterior(), postSeen[i]) << i;
	}
}

// processFrame(lastFrame()) hands the frame's cells to tiers 1 and 2 and
// reports the tiers' masks without copying them; building the next frame
// leaves the cells the tiers hold alone (it builds into another buffer).
TEST(MotionGrids, LastFrameCellsAndMasksAreHandedOverWithoutACopy)
{
	GridParams p = test::paperGrids();
	MotionGrids mg(p);
	using namespace bims::maps::test;
	const auto scene = room();
	std::vector<VoxelKey> before;
	for (int f = 0; f < 4; ++f)
	{
		const mrpt::poses::CPose3D T(0.1 * f, 0.05 * f, 1, 0.1 * f, 0, 0);
		auto scan = renderScan(scene, T, 40, 30, 60, f);
		const auto& fr = mg.buildFrame(*scan, T);
		// The tiers still hold the previous frame's cells, unchanged.
		ASSERT_EQ(mg.background()->lastCells(), before) << f;
		if (f > 0)
		{
			ASSERT_NE(fr.cells, before) << f;
		}
		const auto& res = mg.processFrame(mg.lastFrame(), nullptr);
		EXPECT_EQ(mg.background()->lastCells().data(), fr.cells.data());
		EXPECT_EQ(mg.flowConsistency()->lastCells().data(), fr.cells.data());
		EXPECT_EQ(&res.maskTier1(), &mg.background()->lastMovingMask());
		EXPECT_EQ(&res.maskTier2(), &mg.flowConsistency()->lastMovingMask());
		EXPECT_EQ(res.maskTier1().width, 40);
		before = fr.cells;
	}
	// A caller's frame is copied: the caller may change it afterwards.
	FrameCloud own = mg.lastFrame();
	mg.processFrame(own, nullptr);
	EXPECT_NE(mg.background()->lastCells().data(), own.cells.data());
	EXPECT_EQ(mg.background()->lastCells(), own.cells);
	own.cells.clear();
	EXPECT_EQ(mg.background()->lastCells(), before);
	// A frame skipped for its pose has no masks.
	const auto scan = renderScan(scene, mrpt::poses::CPose3D(), 40, 30, 60, 9);
	const double nan = std::nan("");
	const auto& bad = mg.processFrame(
	    *scan, mrpt::poses::CPose3D(nan, 0, 0, 0, 0, 0), nullptr);
	EXPECT_TRUE(bad.stats.badPose);
	EXPECT_TRUE(bad.maskTier1().data.empty());
	EXPECT_TRUE(bad.maskTier2().data.empty());
}

// probabilityAt() of tiers 1 and 2: the posterior of the voxel if the last
// frame hit it, nullopt otherwise (also for a voxel hit only before).
TEST(MotionGrids, TierProbabilityIsTheLastFramesPosterior)
{
	GridParams p = test::paperGrids();
	p.voxel_size = 0.1;
	MotionGrids mg(p);
	const VoxelKey a{3, 0, 0}, b{5, 1, 0};
	mg.processFrame(frameAt(p, {a, b}, {4, 1}, {0, 0, 0}, 1), nullptr);
	for (const CMotionGridBase* m :
	     {static_cast<const CMotionGridBase*>(mg.background().get()),
	      static_cast<const CMotionGridBase*>(mg.flowConsistency().get())})
		for (size_t i = 0; i < 2; ++i)
		{
			const auto pr = m->probabilityAt(m->centerOf(m->lastCells()[i]));
			ASSERT_TRUE(pr.has_value());
			EXPECT_DOUBLE_EQ(
			    *pr, 1 / (1 + std::exp(-double(m->lastPosterior()[i]))));
		}
	EXPECT_FALSE(mg.background()->probabilityAt({-5, 0, 0}).has_value());
	mg.processFrame(frameAt(p, {b}, {2}, {0, 0, 0}, 2), nullptr);
	EXPECT_FALSE(mg.background()
	                 ->probabilityAt(mg.background()->centerOf(a))
	                 .has_value());
	EXPECT_TRUE(mg.background()
	                ->probabilityAt(mg.background()->centerOf(b))
	                .has_value());
}

// The per-cell Diff/notDiff counts of posterior() (packed in one word while
// no cell has 2^16 readings) are countLabels()'s: the posterior is
// tier 1 + flowPosterior(0, k, l) of those counts, bit for bit, on both
// sides of the packing limit.
TEST(FlowGrid, PosteriorCountsTheLabelsAsCountLabelsOnBothSidesOf65536)
{
	GridParams p = test::paperGrids();
	p.voxel_size = 0.1;
	CFlowConsistencyGrid g(p);
	const double logLambda = std::log(p.flow_lambda);
	std::mt19937 rng(7);
	for (const uint32_t big : {40u, 65535u, 65536u, 70001u})
	{
		const std::vector<VoxelKey> keys = {
		    {0, 0, 0}, {1, 0, 0}, {0, 3, 1}, {5, 5, 5}};
		const std::vector<uint32_t> counts = {big, 7, 31, 1};
		std::vector<mrpt::math::TPoint3Df> pts;
		std::vector<uint32_t> pix;
		for (size_t i = 0; i < keys.size(); ++i)
			for (uint32_t j = 0; j < counts[i]; ++j)
			{
				pts.emplace_back(float((keys[i].x + 0.5) * p.voxel_size),
				                 float((keys[i].y + 0.5) * p.voxel_size),
				                 float((keys[i].z + 0.5) * p.voxel_size));
				pix.push_back(uint32_t(pix.size()));
			}
		bims::sensors::PinholeCamera K;
		K.width = int(pix.size());
		K.height = 1;
		K.fx = K.fy = 1;
		FrameCloud fr;
		FrameCloudBuilder(p).buildFromPoints(pts, pix, {0, 0, -1}, fr, K);
		ASSERT_EQ(fr.cells.size(), keys.size());
		PixelLabels lab(K.width, 1);
		// The big cell all Diff (its count reaches the packing limit), the
		// others at random.
		for (size_t j = 0; j < lab.label.size(); ++j)
			lab.label[j] = j < big ? int8_t(1) : int8_t(int(rng() % 3) - 1);
		std::vector<float> t1(fr.cells.size());
		for (auto& v : t1) v = float(rng() % 200) / 40.f - 2.5f;
		std::vector<uint32_t> k, l;
		CFlowConsistencyGrid::countLabels(fr, lab, k, l);
		std::vector<float> post;
		g.posterior(fr, lab, t1, post);
		ASSERT_EQ(post.size(), fr.cells.size());
		size_t labelled = 0, counted = 0;
		for (const auto v : lab.label) labelled += v == 0 || v == 1;
		for (size_t i = 0; i < fr.cells.size(); ++i) counted += k[i] + l[i];
		ASSERT_EQ(counted, labelled);
		for (size_t i = 0; i < fr.cells.size(); ++i)
		{
			EXPECT_EQ(
			    post[i],
			    float(t1[i] + flowPosterior(0, p.flow_transition_tau, p.p_miss,
			                                logLambda, k[i], l[i], false)))
			    << big << " cell " << i << " k " << k[i] << " l " << l[i];
		}
	}
}

TEST(FlowGrid, LabelsMoveTheDecisionAsTheModelSays)
{
	GridParams p = test::paperGrids();
	p.flow_transition_tau = 0.05;
	MotionGrids mg(p);
	const VoxelKey k{0, 0, 0};
	// Build a background voxel (tier 1 negative) over a few frames.
	for (int f = 1; f <= 4; ++f)
		mg.processFrame(frameAt(p, {k}, {3}, {0, 0, 0}, f), nullptr);
	const double l1 = mg.background()->lastPosterior()[0];
	ASSERT_LT(l1, 0);
	ASSERT_GT(l1, -std::log(0.95 / 0.05));  // within tau's reach
	// All readings Diff: tier 2 overturns tier 1.
	auto fr = frameAt(p, {k}, {3}, {0, 0, 0}, 5);
	fr.K.width = 3;
	fr.K.height = 1;
	PixelLabels diff(3, 1, 1), same(3, 1, 0);
	std::vector<float> post;
	std::vector<float> t1 = {float(l1)};
	mg.flowConsistency()->posterior(fr, diff, t1, post);
	EXPECT_GT(post[0], 0);
	mg.flowConsistency()->posterior(fr, same, t1, post);
	EXPECT_LT(post[0], l1);
	// Veto: Diff readings alone carry no evidence.
	GridParams pv = p;
	pv.flow_evidence = FlowEvidence::Veto;
	CFlowConsistencyGrid veto(pv);
	veto.posterior(fr, diff, t1, post);
	EXPECT_NEAR(post[0], l1, 1e-6);
	// Wrong label size is an error, not a silently wrong answer.
	EXPECT_THROW(
	    mg.flowConsistency()->posterior(fr, PixelLabels(4, 1, 1), t1, post),
	    std::invalid_argument);
}

namespace
{
std::vector<uint8_t> bytesOf(const mrpt::serialization::CSerializable& o)
{
	mrpt::io::CMemoryStream buf;
	// MRPT grows the buffer 4 KiB at a time, a copy each: quadratic in the
	// grid's size (minutes under AddressSanitizer, whose realloc copies)
	buf.setAllocBlockSize(size_t{1} << 24);
	auto arch = mrpt::serialization::archiveFrom(buf);
	arch << o;
	const auto* d = static_cast<const uint8_t*>(buf.getRawBufferData());
	return std::vector<uint8_t>(d, d + buf.getTotalBytesCount());
}

// Frames of a room with a moving box at 1 cm (more blocks than 1 MiB holds).
std::vector<FrameCloud> framesOver(const GridParams& p, int n)
{
	using namespace bims::maps::test;
	auto scene = room();
	FrameCloudBuilder b(p);
	std::vector<FrameCloud> out(n);
	for (int f = 0; f < n; ++f)
	{
		scene.push_back({{2.0, -1.0 + 0.2 * f, 0}, {2.3, -0.7 + 0.2 * f, 1.5}});
		const mrpt::poses::CPose3D T(0.1 * f, 0.05 * f, 1, 0.1 * f, 0, 0);
		auto scan = renderScan(scene, T, 160, 120, 60, f);
		b.build(*scan, T, out[f]);
		out[f].timestamp =
		    mrpt::Clock::time_point(mrpt::Clock::duration(f + 1));
		scene.pop_back();
	}
	return out;
}
}  // namespace

// MotionGrids stores tiers 1 and 2 in one sweep (storePair): the same maps
// (cells, stamps, budget accounting, masks, last frame) as two store()s,
// also when the memory budget leaves cells out.
TEST(MotionGrids, StorePairEqualsTwoStores)
{
	for (const double mb : {256.0, 1.0})
	{
		GridParams p = test::paperGrids();
		p.voxel_size = 0.01;
		p.max_memory_mb = mb;
		CBackgroundSubtractionGrid a1(p), b1(p);
		CFlowConsistencyGrid a2(p), b2(p);
		bool over = false;
		int f = 0;
		for (const auto& fr : framesOver(p, 5))
		{
			const size_t m = fr.cells.size();
			std::vector<float> p1(m), p2(m);
			for (size_t i = 0; i < m; ++i)
			{
				p1[i] = float((i * 7 + f) % 5) - 2.f;
				p2[i] = float((i * 3 + f) % 7) - 3.f;
			}
			a1.store(fr, p1);
			a2.store(fr, p2);
			auto cells = std::make_shared<std::vector<VoxelKey>>(fr.cells);
			auto q1 = p1, q2 = p2;
			CMotionGridBase::storePair(b1, std::move(q1), b2, std::move(q2), fr,
			                           cells);
			ASSERT_EQ(bytesOf(a1), bytesOf(b1)) << mb << " " << f;
			ASSERT_EQ(bytesOf(a2), bytesOf(b2)) << mb << " " << f;
			ASSERT_EQ(a1.lastMovingMask().data, b1.lastMovingMask().data);
			ASSERT_EQ(a2.lastMovingMask().data, b2.lastMovingMask().data);
			ASSERT_EQ(b1.lastPosterior(), p1);
			ASSERT_EQ(b2.lastPosterior(), p2);
			ASSERT_EQ(b1.lastCells(), fr.cells);
			ASSERT_EQ(b2.lastCells(), fr.cells);
			for (const auto& k : fr.cells) over |= !b1.storage().find(k);
			++f;
		}
		EXPECT_EQ(over, mb < 2) << "the small budget must leave cells out";
		std::vector<float> p1(1), p2(1);
		auto cells = std::make_shared<std::vector<VoxelKey>>();
		EXPECT_THROW(
		    CMotionGridBase::storePair(b1, std::move(p1), b1, std::move(p2),
		                               FrameCloud(), cells),
		    std::invalid_argument);
	}
}

// integrate() finds the frame's cells during the update; beginFrame() +
// integratePending() find them first: the same map and O-, also over
// budget.
TEST(OccupancyGrid, IntegrateEqualsBeginFrameThenPending)
{
	for (const double mb : {256.0, 1.0})
	{
		GridParams p = test::paperGrids();
		p.voxel_size = 0.01;
		p.max_memory_mb = mb;
		COccupancyBayesGrid a(p), b(p);
		bool over = false;
		int f = 0;
		for (const auto& fr : framesOver(p, 5))
		{
			std::vector<float> pa, pb;
			a.integrate(fr, &pa);
			b.beginFrame(fr, pb);
			b.integratePending(fr, nullptr);
			ASSERT_EQ(pa, pb) << mb << " " << f;
			ASSERT_EQ(bytesOf(a), bytesOf(b)) << mb << " " << f;
			for (const auto& k : fr.cells) over |= !a.storage().find(k);
			++f;
		}
		EXPECT_EQ(over, mb < 2) << "the small budget must leave cells out";
	}
}

// setDeferDecay(): tier 0's decay of a frame applied later (as the pipeline
// does on a thread of its own; here after the next frame's cloud is built)
// or by the next processFrame() gives the same maps, masks and posteriors as
// the decay in processFrame(); meanwhile tier 0 lacks exactly the decay.
TEST(MotionGrids, DeferredDecayGivesTheSameMapsAndMasks)
{
	using namespace bims::maps::test;
	for (const DecayMode mode :
	     {DecayMode::Raycast, DecayMode::Frustum, DecayMode::All})
		for (const bool exclude : {false, true})
		{
			GridParams p = test::paperGrids();
			p.voxel_size = 0.05;
			p.decay = mode;
			p.exclude_moving = exclude;
			MotionGrids a(p), b(p);
			b.setDeferDecay(true);
			// tier 0 of b as it is (occupancy() would apply a pending decay)
			const auto t0b = b.occupancy();
			auto scene = room();
			const int n = 6;
			bool lacked = false;  // tier 0 of b without the decay differed
			std::vector<uint8_t> aBefore;  // a's tier 0 after the last frame
			for (int f = 0; f < n; ++f)
			{
				SCOPED_TRACE(::testing::Message()
				             << "decay " << int(mode) << ", exclude " << exclude
				             << ", frame " << f);
				scene.push_back(
				    {{2.0, -1.0 + 0.2 * f, 0}, {2.3, -0.7 + 0.2 * f, 1.5}});
				const mrpt::poses::CPose3D T(0.1 * f, 0.05 * f, 1, 0.1 * f, 0,
				                             0);
				auto scan = renderScan(scene, T, 80, 60, 60, f);
				const auto& ra = a.processFrame(*scan, T, nullptr);
				// the next frame's cloud first, then the last frame's decay
				// (even frames); frame 3 reads tier 0 through occupancy(),
				// which applies it; the others leave it to processFrame()
				b.buildFrame(*scan, T);
				if (f % 2 == 0 && b.decayPending())
				{
					lacked |= bytesOf(*t0b) != aBefore;
					b.applyPendingDecay();
					EXPECT_TRUE(bytesOf(*t0b) == aBefore);
				}
				else if (f == 3 && b.decayPending())
				{
					// a const query changes nothing: it refuses the map
					// that lacks the decay
					EXPECT_THROW(std::as_const(b).occupancy(),
					             std::logic_error);
					EXPECT_TRUE(b.decayPending());
					EXPECT_TRUE(bytesOf(*b.occupancy()) == aBefore);
					EXPECT_FALSE(b.decayPending());
				}
				const auto& rb = b.processFrame(b.lastFrame(), nullptr);
				EXPECT_EQ(b.decayPending(), mode != DecayMode::All);
				EXPECT_EQ(ra.maskTier1().data, rb.maskTier1().data);
				EXPECT_EQ(ra.maskTier2().data, rb.maskTier2().data);
				EXPECT_EQ(a.background()->lastPosterior(),
				          b.background()->lastPosterior());
				EXPECT_EQ(a.flowConsistency()->lastPosterior(),
				          b.flowConsistency()->lastPosterior());
				EXPECT_EQ(ra.movingTier1, rb.movingTier1);
				aBefore = bytesOf(*a.occupancy());
			}
			b.applyPendingDecay();
			EXPECT_FALSE(b.decayPending());
			EXPECT_TRUE(bytesOf(*a.occupancy()) == bytesOf(*b.occupancy()))
			    << "decay " << int(mode) << ", exclude " << exclude;
			EXPECT_EQ(lacked, mode != DecayMode::All)
			    << "decay " << int(mode) << ": the deferred decay must change "
			    << "tier 0 (else this test proves nothing)";
		}
}

// While a decay is pending, tier 0 refuses the next frame (the caller must
// apply it first); clear() drops it.
TEST(OccupancyGrid, PendingDecayRefusesTheNextFrame)
{
	GridParams p = test::paperGrids();
	p.voxel_size = 0.05;
	p.decay = DecayMode::Raycast;
	const auto frames = framesOver(p, 2);
	COccupancyBayesGrid g(p);
	g.setDeferDecay(true);
	g.integrate(frames[0]);
	ASSERT_TRUE(g.decayPending());
	EXPECT_THROW(g.integrate(frames[1]), std::logic_error);
	std::vector<float> prior;
	EXPECT_THROW(g.beginFrame(frames[1], prior), std::logic_error);
	g.applyPendingDecay();
	EXPECT_FALSE(g.decayPending());
	EXPECT_NO_THROW(g.integrate(frames[1]));
	g.clear();
	EXPECT_FALSE(g.decayPending());
	EXPECT_NO_THROW(g.integrate(frames[0]));
}

// A frame without a flow tier (depth only: flowOff) excludes what tier 1
// calls moving from tier 0 (exclude_moving); the same frame without labels
// and without flowOff (a first frame) excludes nothing. Tiers 1 and 2 are
// the same either way (tier 2 without labels equals tier 1).
TEST(MotionGrids, WithoutAFlowTierTier1DecidesWhatTier0LeavesOut)
{
	GridParams p;  // the tuned model (config/default.ini)
	p.voxel_size = 0.1;
	p.exclude_moving = true;
	p.decay = DecayMode::Raycast;
	// c is seen through b for 15 frames (b free), then b is hit
	const VoxelKey a{3, 4, 0}, b{2, 0, 0}, c{6, 0, 0};
	double lb[2] = {0, 0}, la[2] = {0, 0};
	std::vector<float> post[2];
	for (int off = 0; off < 2; ++off)
	{
		MotionGrids mg(p);
		for (int f = 1; f <= 15; ++f)
			mg.processFrame(frameAt(p, {a, c}, {4, 4}, {0.05, 0.05, 0.05}, f),
			                nullptr, off == 1);
		const auto cb = mg.occupancy()->centerOf(b);
		const auto ca = mg.occupancy()->centerOf(a);
		const double before = mg.occupancy()->logOddsAt(cb);
		ASSERT_LT(before, 0) << "b is known free";
		const auto& r =
		    mg.processFrame(frameAt(p, {a, b}, {4, 4}, {0.05, 0.05, 0.05}, 16),
		                    nullptr, off == 1);
		ASSERT_EQ(r.movingTier1, 1u) << "b appeared in free space";
		EXPECT_EQ(r.movingTier2, r.movingTier1);
		lb[off] = mg.occupancy()->logOddsAt(cb) - before;
		la[off] = mg.occupancy()->logOddsAt(ca);
		post[off] = mg.background()->lastPosterior();
	}
	EXPECT_GT(lb[0], 0) << "without flowOff tier 0 folds the mover in";
	EXPECT_EQ(lb[1], 0) << "with flowOff tier 0 leaves the mover out";
	EXPECT_EQ(la[0], la[1]) << "the static voxel is folded in either way";
	EXPECT_EQ(post[0], post[1]);
}
