// The model options beyond the paper's literal reading (docs/model.md,
// "Beyond the literal model"): the prior of unseen space (p_unknown), the
// background neighbourhood of tier 1 (bg_neighbourhood) and the static map
// that leaves moving voxels out (exclude_moving). Each is checked against
// the closed forms of closed_form.h and against the paper's behaviour it
// replaces.
#include <bims/common/config.h>
#include <bims/maps/closed_form.h>
#include <bims/maps/motion_grids.h>

#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>

#include <gtest/gtest.h>

#include <cmath>

#include "scene_raycaster.h"
#include "test_util.h"

using namespace bims::maps;
using bims::maps::test::frameAt;

namespace
{
double hit(const GridParams& p, uint32_t n)
{
	return hitLogOdds(p.p_miss, std::log(p.reading_lambda), n);
}
}  // namespace

TEST(ModelOptions, UnknownPriorIsTheValueOfUnseenSpace)
{
	for (auto mode : {DecayMode::All, DecayMode::Frustum, DecayMode::Raycast})
	{
		GridParams p = test::paperGrids();
		p.decay = mode;
		p.p_max = 0.999;
		p.p_unknown = 0.97;
		MotionGrids mg(p);
		const VoxelKey a{0, 0, 10}, b{3, 0, 10};
		// Frames 1..5 hit a only; b is never seen.
		for (int f = 1; f <= 5; ++f)
			mg.processFrame(frameAt(p, {a}, {3}, {0, 0, 0}, f), nullptr);
		const double lu = logit(0.97);
		EXPECT_NEAR(fromFixed(mg.occupancy()->logOddsFixed(b)), lu, 1e-5)
		    << bims::choiceName(mode);
		// b's first hit: tier 0 starts from p_unknown (not from 0.5 decayed
		// by 5 frames), tier 1 reads it as O-.
		mg.processFrame(frameAt(p, {b}, {3}, {0, 0, 0}, 6), nullptr);
		EXPECT_NEAR(fromFixed(mg.occupancy()->logOddsFixed(b)),
		            std::min(lu + hit(p, 3), logit(p.p_max)), 1e-5);
		ASSERT_EQ(mg.background()->lastPosterior().size(), 1u);
		const double want = backgroundPosterior(lu, p.bg_transition_eps,
		                                        p.p_miss, std::log(1.0), 3);
		EXPECT_NEAR(mg.background()->lastPosterior()[0], want, 1e-5);
		EXPECT_LT(want, 0);  // a newly seen surface is not flagged
	}
}

TEST(ModelOptions, PaperPriorOfUnseenSpaceDecaysUnderDecayAll)
{
	GridParams p = test::paperGrids();  // p_unknown = 0: the paper
	MotionGrids mg(p);
	const VoxelKey a{0, 0, 10}, b{3, 0, 10};
	for (int f = 1; f <= 5; ++f)
		mg.processFrame(frameAt(p, {a}, {3}, {0, 0, 0}, f), nullptr);
	mg.processFrame(frameAt(p, {b}, {3}, {0, 0, 0}, 6), nullptr);
	// O- of b = 0.5 decayed by 5 frames, clamped: p_min; tier 1 flags it.
	const double want = backgroundPosterior(logit(p.p_min), p.bg_transition_eps,
	                                        p.p_miss, 0, 3);
	EXPECT_NEAR(mg.background()->lastPosterior()[0], want, 1e-5);
	EXPECT_GT(want, 0);
}

TEST(ModelOptions, RayNeighbourExplainsDepthNoiseInFrontOfASurface)
{
	// A surface voxel on the optical axis, established over 5 frames; then
	// one reading lands one voxel in front of it (depth noise), another one
	// voxel to its side.
	const VoxelKey surface{0, 0, 20}, front{0, 0, 19}, side{1, 0, 20};
	for (auto nb : {BgNeighbourhood::None, BgNeighbourhood::Ray,
	                BgNeighbourhood::Faces, BgNeighbourhood::Block})
	{
		GridParams p = test::paperGrids();
		p.decay = DecayMode::All;
		p.bg_neighbourhood = nb;
		MotionGrids mg(p);
		for (int f = 1; f <= 5; ++f)
			mg.processFrame(frameAt(p, {surface}, {5}, {0.025, 0.025, 0}, f),
			                nullptr);
		const double lSurface =
		    fromFixed(mg.occupancy()->logOddsFixed(surface));
		mg.processFrame(
		    frameAt(p, {surface, front, side}, {5, 1, 1}, {0.025, 0.025, 0}, 6),
		    nullptr);
		const auto& post = mg.background()->lastPosterior();
		const auto& cells = mg.background()->lastCells();
		ASSERT_EQ(post.size(), 3u);
		for (size_t i = 0; i < 3; ++i)
		{
			const uint32_t n = cells[i] == surface ? 5 : 1;
			const bool explained =
			    cells[i] == surface ||
			    (cells[i] == front && nb != BgNeighbourhood::None) ||
			    (cells[i] == side && (nb == BgNeighbourhood::Faces ||
			                          nb == BgNeighbourhood::Block));
			// Unexplained: the paper's O- (never-touched space, decayed to
			// p_min); explained: the surface's O-.
			const double o = explained ? lSurface : logit(p.p_min);
			EXPECT_NEAR(
			    post[i],
			    backgroundPosterior(o, p.bg_transition_eps, p.p_miss, 0, n),
			    1e-5)
			    << bims::choiceName(nb) << " cell " << i;
			EXPECT_EQ(post[i] > 0, !explained)
			    << bims::choiceName(nb) << " cell " << i;
		}
	}
}

TEST(ModelOptions, ExcludeMovingKeepsAStoppedObjectFlagged)
{
	// A voxel seen occupied (frames 1-3), then empty (4-14: it decays to
	// p_min), then an object arrives in it and stays put (15-24). The paper
	// folds the object's readings into tier 0, so tier 1 calls it background
	// two frames later; with exclude_moving the voxel keeps its belief while
	// tier 1 calls it moving, and the object stays flagged.
	const VoxelKey wall{0, 0, 40}, obj{0, 0, 20};
	for (bool exclude : {false, true})
	{
		GridParams p = test::paperGrids();
		p.decay = DecayMode::All;
		p.p_unknown = 0.97;
		p.exclude_moving = exclude;
		MotionGrids mg(p);
		mg.setDecisionTier(1);
		const PixelLabels noFlow;  // labels given, none on any reading
		// The first frame has no labels (as the pipeline's frame 0): it is
		// folded in whole.
		for (int f = 1; f <= 14; ++f)
		{
			const auto fr = f <= 3
			                    ? frameAt(p, {wall, obj}, {5, 5}, {0, 0, 0}, f)
			                    : frameAt(p, {wall}, {5}, {0, 0, 0}, f);
			mg.processFrame(fr, f == 1 ? nullptr : &noFlow);
		}
		const LogOddsFx before = mg.occupancy()->logOddsFixed(obj);
		EXPECT_EQ(before, mg.occupancy()->minFixed());
		int flagged = 0;
		for (int f = 15; f <= 24; ++f)
		{
			mg.processFrame(frameAt(p, {wall, obj}, {5, 5}, {0, 0, 0}, f),
			                &noFlow);
			const auto& cells = mg.background()->lastCells();
			const auto& post = mg.background()->lastPosterior();
			for (size_t i = 0; i < cells.size(); ++i)
				if (cells[i] == obj) flagged += post[i] > 0;
		}
		if (exclude)
		{
			EXPECT_EQ(flagged, 10);
			// Held: no hit and no miss in tier 0.
			EXPECT_EQ(mg.occupancy()->logOddsFixed(obj), before);
		}
		else
		{
			EXPECT_EQ(flagged, 2);
			EXPECT_GT(mg.occupancy()->logOddsAt({0.025, 0.025, 1.025}), 0);
		}
		// The wall is background either way.
		EXPECT_FALSE(mg.background()->wasMovingAtLastHit(wall));
	}
}

TEST(ModelOptions, ExcludeMovingFollowsTheDecisionTier)
{
	// Tier 2 with Diff labels on the object flags it even where tier 1 does
	// not; the static map then leaves it out.
	GridParams p = test::paperGrids();
	p.exclude_moving = true;
	p.p_unknown = 0.97;
	p.p_max = 0.999;
	p.bg_transition_eps = 0.001;
	p.flow_transition_tau = 0.03;
	MotionGrids mg(p);
	EXPECT_EQ(mg.decisionTier(), 2);
	EXPECT_THROW(mg.setDecisionTier(3), std::invalid_argument);
	const VoxelKey obj{0, 0, 20};
	// Unseen space, so tier 1 says static (p_unknown); the labels say Diff.
	FrameCloud f = frameAt(p, {obj}, {4}, {0, 0, 0}, 1);
	f.K.width = 4;
	f.K.height = 1;
	for (uint32_t j = 0; j < 4; ++j) f.pixel[j] = j;
	PixelLabels diff(4, 1, 1);
	mg.processFrame(f, &diff);
	EXPECT_LT(mg.background()->lastPosterior()[0], 0);
	EXPECT_GT(mg.flowConsistency()->lastPosterior()[0], 0);
	// Held in tier 0: still the unknown prior.
	EXPECT_NEAR(fromFixed(mg.occupancy()->logOddsFixed(obj)), logit(0.97),
	            1e-5);
	// The same frame with notDiff labels is folded in.
	FrameCloud g = f;
	g.timestamp = mrpt::Clock::time_point(mrpt::Clock::duration(2));
	PixelLabels same(4, 1, 0);
	mg.processFrame(g, &same);
	EXPECT_LT(mg.flowConsistency()->lastPosterior()[0], 0);
	EXPECT_GT(fromFixed(mg.occupancy()->logOddsFixed(obj)), logit(0.97));
}

TEST(ModelOptions, NewParametersSurviveSerialisationAndIni)
{
	GridParams p = test::paperGrids();
	p.p_unknown = 0.9;
	p.bg_neighbourhood = BgNeighbourhood::Ray;
	p.exclude_moving = true;
	p.exclude_by = ExcludeBy::Either;
	CFlowConsistencyGrid m(p);
	mrpt::io::CMemoryStream buf;
	auto arch = mrpt::serialization::archiveFrom(buf);
	arch << m;
	buf.Seek(0);
	auto back =
	    std::dynamic_pointer_cast<CFlowConsistencyGrid>(arch.ReadObject());
	ASSERT_TRUE(back);
	EXPECT_EQ(back->params(), p);

	mrpt::config::CConfigFileMemory ini(
	    "[grids]\np_unknown=0.9\nbg_neighbourhood=ray\nexclude_moving=true\n"
	    "exclude_by=either\n");
	GridParams q = test::paperGrids();
	q.loadFromConfigFile(ini, "grids");
	EXPECT_EQ(q, p);
	mrpt::config::CConfigFileMemory bad("[grids]\nbg_neighbourhood=sphere\n");
	EXPECT_THROW(q.loadFromConfigFile(bad, "grids"), bims::ConfigError);
	mrpt::config::CConfigFileMemory badBy("[grids]\nexclude_by=tier3\n");
	EXPECT_THROW(q.loadFromConfigFile(badBy, "grids"), bims::ConfigError);
	mrpt::config::CConfigFileMemory range("[grids]\np_unknown=1.5\n");
	EXPECT_THROW(q.loadFromConfigFile(range, "grids"), bims::ConfigError);
}

TEST(ModelOptions, ExcludeByEitherHoldsWhatTier1CallsMovingAgainstTheFlow)
{
	// A voxel seen occupied (frames 1-3), then empty (4-14: decayed to
	// p_min); at frame 15 an object is in it whose flow looks consistent
	// (notDiff: a pendulum at its turning point). Tier 2 then calls it
	// static; with exclude_by = decision tier 0 folds it in, with either
	// (tier 1 calls it moving) it is held.
	const VoxelKey wall{0, 0, 40}, obj{0, 0, 20};
	for (const ExcludeBy by :
	     {ExcludeBy::Decision, ExcludeBy::Either, ExcludeBy::Auto})
	{
		GridParams p = test::paperGrids();
		p.decay = DecayMode::All;
		p.p_unknown = 0.97;
		p.exclude_moving = true;
		p.exclude_by = by;
		p.flow_transition_tau = 0.001;  // the flow can overrule tier 1
		MotionGrids mg(p);
		for (int f = 1; f <= 14; ++f)
			mg.processFrame(f <= 3
			                    ? frameAt(p, {wall, obj}, {5, 5}, {0, 0, 0}, f)
			                    : frameAt(p, {wall}, {5}, {0, 0, 0}, f),
			                nullptr);
		const LogOddsFx before = mg.occupancy()->logOddsFixed(obj);
		FrameCloud fr = frameAt(p, {wall, obj}, {5, 5}, {0, 0, 0}, 15);
		fr.K.width = 10;
		fr.K.height = 1;
		for (uint32_t j = 0; j < 10; ++j) fr.pixel[j] = j;
		const PixelLabels notDiff(10, 1, 0);
		mg.processFrame(fr, &notDiff);
		const auto& cells = mg.background()->lastCells();
		size_t io = cells.size();
		for (size_t i = 0; i < cells.size(); ++i)
			if (cells[i] == obj) io = i;
		ASSERT_LT(io, cells.size());
		EXPECT_GT(mg.background()->lastPosterior()[io], 0)
		    << bims::choiceName(by);
		EXPECT_LT(mg.flowConsistency()->lastPosterior()[io], 0)
		    << bims::choiceName(by);
		if (by == ExcludeBy::Decision)
			EXPECT_GT(mg.occupancy()->logOddsFixed(obj), before);
		else  // either, and auto without ray casting
			EXPECT_EQ(mg.occupancy()->logOddsFixed(obj), before)
			    << bims::choiceName(by);
	}
}

// neighbourhoodMaxPrior() against its plain definition, for every
// neighbourhood, on frames of a room with thousands of voxels over many
// blocks (and neighbours in blocks that do not exist): the largest prior
// of the neighbours tier 0 has observed, and the cell's own prior.
TEST(ModelOptions, NeighbourhoodMaxPriorEqualsThePlainDefinition)
{
	using namespace bims::maps::test;
	for (const DecayMode mode : {DecayMode::Raycast, DecayMode::All})
	{
		GridParams p = paperGrids();
		p.voxel_size = 0.02;
		p.decay = mode;
		COccupancyBayesGrid g(p);
		FrameCloudBuilder b(p);
		auto scene = room();
		FrameCloud f;
		size_t explained = 0;
		for (int k = 0; k < 5; ++k)
		{
			scene.push_back(
			    {{2.0, -1.0 + 0.1 * k, 0}, {2.3, -0.7 + 0.1 * k, 1.5}});
			const mrpt::poses::CPose3D T(0.05 * k, 0.02 * k, 1, 0.05 * k, 0, 0);
			b.build(*renderScan(scene, T, 160, 120, 60, k), T, f);
			std::vector<float> prior, out;
			g.priorLogOdds(f, prior);
			for (const BgNeighbourhood nb :
			     {BgNeighbourhood::Ray, BgNeighbourhood::Faces,
			      BgNeighbourhood::Block})
			{
				g.neighbourhoodMaxPrior(f, prior, nb, out);
				ASSERT_EQ(out.size(), f.cells.size());
				const double s = p.voxel_size;
				const auto& o = f.origin_W;
				for (size_t i = 0; i < f.cells.size(); ++i)
				{
					const VoxelKey& c = f.cells[i];
					std::vector<VoxelKey> nbs;
					if (nb == BgNeighbourhood::Ray)
					{
						const auto ctr = g.centerOf(c);
						double dx = ctr.x - o.x, dy = ctr.y - o.y,
						       dz = ctr.z - o.z;
						const double n = std::sqrt(dx * dx + dy * dy + dz * dz);
						dx *= s / n, dy *= s / n, dz *= s / n;
						for (int sg : {-1, 1})
							nbs.push_back(
							    g.keyOf({ctr.x + sg * dx, ctr.y + sg * dy,
							             ctr.z + sg * dz}));
					}
					else
						for (int z = -1; z <= 1; ++z)
							for (int y = -1; y <= 1; ++y)
								for (int x = -1; x <= 1; ++x)
								{
									const int m =
									    std::abs(x) + std::abs(y) + std::abs(z);
									if (m > 0 && (m == 1 ||
									              nb == BgNeighbourhood::Block))
										nbs.push_back(
										    {c.x + x, c.y + y, c.z + z});
								}
					float want = prior[i];
					for (const auto& n : nbs)
					{
						const auto* cell = g.storage().find(n);
						if (n == c || !cell || cell->stamp == 0) continue;
						want =
						    std::max(want, float(fromFixed(g.logOddsFixed(n))));
					}
					explained += want != prior[i];
					ASSERT_EQ(out[i], want)
					    << "frame " << k << ", " << bims::choiceName(nb)
					    << ", cell " << i;
				}
			}
			g.integrate(f);
		}
		EXPECT_GT(explained, 1000u) << "the neighbours must matter";
	}
}
