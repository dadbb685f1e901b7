// Bad input: skipped and counted, never a crash or unbounded growth.
#include <bims/common/options.h>
#include <bims/maps/motion_grids.h>

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "scene_raycaster.h"
#include "test_util.h"

using namespace bims::maps;

TEST(BadInput, NonFiniteFarAndHugePointsAreSkippedAndCounted)
{
	GridParams p = test::paperGrids();
	p.max_range = 5;
	p.extent = 100;
	COccupancyBayesGrid g(p);
	const float nan = std::numeric_limits<float>::quiet_NaN();
	const float inf = std::numeric_limits<float>::infinity();
	std::vector<mrpt::math::TPoint3Df> pts = {
	    {1, 0, 0},     {nan, 0, 0},      {0, inf, 0}, {6, 0, 0},
	    {1e12f, 0, 0}, {-3e9f, 2e9f, 1}, {0, 1, 0}};
	FrameCloudBuilder b(p);
	FrameCloud f;
	b.buildFromPoints(pts, {}, {0, 0, 0}, f);
	EXPECT_EQ(f.stats.valid, 2u);
	EXPECT_EQ(f.stats.nonFinite, 2u);
	EXPECT_EQ(f.stats.beyondRange, 1u);
	EXPECT_EQ(f.stats.outsideExtent, 2u);
	g.integrate(f);
	EXPECT_EQ(g.cellsAbove(0.5).size(), 2u);
}

TEST(BadInput, NanPoseSkipsTheFrame)
{
	using namespace bims::maps::test;
	GridParams p = test::paperGrids();
	CBackgroundSubtractionGrid t1(p);
	COccupancyBayesGrid t0(p);
	auto scan = renderScan(room(), mrpt::poses::CPose3D(0, 0, 1, 0, 0, 0), 32,
	                       24, 60, 0);
	const mrpt::poses::CPose3D bad(std::nan(""), 0, 1, 0, 0, 0);
	EXPECT_FALSE(t0.insertObservation(*scan, bad));
	EXPECT_FALSE(t1.insertObservation(*scan, bad));
	EXPECT_EQ(t0.badPoseFrames(), 1u);
	EXPECT_EQ(t0.frameCount(), 0u);
	MotionGrids mg(p);
	const auto& r = mg.processFrame(*scan, bad, nullptr);
	EXPECT_TRUE(r.stats.badPose);
	EXPECT_EQ(mg.occupancy()->frameCount(), 0u);
}

TEST(BadInput, ZeroDepthAndWrongCameraSize)
{
	using namespace bims::maps::test;
	GridParams p = test::paperGrids();
	auto scan = renderScan(room(), mrpt::poses::CPose3D(0, 0, 1, 0, 0, 0), 32,
	                       24, 60, 0);
	for (int u = 0; u < 32; ++u) scan->rangeImage(0, u) = 0;
	FrameCloudBuilder b(p);
	FrameCloud f;
	b.build(*scan, mrpt::poses::CPose3D(0, 0, 1, 0, 0, 0), f);
	EXPECT_EQ(f.stats.noDepth, 32u);
	EXPECT_EQ(f.stats.valid, size_t(32 * 23));
	scan->cameraParams.ncols = 64;
	EXPECT_THROW(b.build(*scan, mrpt::poses::CPose3D(), f),
	             std::invalid_argument);
	COccupancyBayesGrid g(p);
	EXPECT_THROW(g.insertObservation(*scan, mrpt::poses::CPose3D()),
	             std::invalid_argument);
}

TEST(BadInput, MemoryStaysWithinTheBudget)
{
	GridParams p = test::paperGrids();
	p.voxel_size = 0.01;
	p.max_memory_mb = 1;
	p.decay = DecayMode::Raycast;
	p.max_range = 50;
	COccupancyBayesGrid g(p);
	std::vector<mrpt::math::TPoint3Df> pts;
	for (int i = 0; i < 2000; ++i)
		pts.emplace_back(float(i % 50) * 0.8f - 20, float(i / 50) * 0.75f - 15,
		                 5);
	FrameCloudBuilder b(p);
	FrameCloud f;
	b.buildFromPoints(pts, {}, {0, 0, 0}, f);
	g.integrate(f);
	EXPECT_LE(g.memoryBytes(), size_t(1) << 20);
	EXPECT_GT(g.totalStats().overBudget, 0u);
}

TEST(BadInput, InvalidParametersAreRejected)
{
	GridParams p = test::paperGrids();
	p.flow_lambda = 1;
	EXPECT_THROW(COccupancyBayesGrid{p}, std::invalid_argument);
	p = test::paperGrids();
	p.p_min = 0.6;
	EXPECT_THROW(p.validate(), std::invalid_argument);
	p = test::paperGrids();
	p.voxel_size = 0.001;
	p.extent = 1e5;
	EXPECT_THROW(p.validate(), std::invalid_argument);
}

namespace
{
/** Sets one real key of a describe() to a value, and lists the real keys
 * with their ranges. */
struct RealKeys : bims::OptionVisitor
{
	std::string key;
	double value = 0;
	std::vector<std::tuple<std::string, double, double>> ranges;

 protected:
	void onReal(const char* k, double& v, double min, double max,
	            const char*) override
	{
		ranges.emplace_back(k, min, max);
		if (key == k) v = value;
	}
	void onInteger(const char*, long&, long, long, const char*) override {}
	void onFlag(const char*, bool&, const char*) override {}
	void onText(const char*, std::string&, const char*) override {}
	void onReals(const char*, double*, std::size_t, double, double,
	             const char*) override
	{
	}
	void onChoice(const char*, std::string&, const std::vector<std::string>&,
	              const char*) override
	{
	}
};
}  // namespace

TEST(BadInput, ValidateChecksEveryRangeOfTheDescriptionAndNamesTheKey)
{
	RealKeys all;
	GridParams{}.describe(all);
	ASSERT_GT(all.ranges.size(), 10u);
	for (const auto& [key, min, max] : all.ranges)
		for (const double bad :
		     {max * 2 + 1, min - 1, std::numeric_limits<double>::quiet_NaN()})
		{
			if (bad >= min && bad <= max) continue;
			GridParams p;
			RealKeys set;
			set.key = key;
			set.value = bad;
			p.describe(set);
			try
			{
				p.validate();
				ADD_FAILURE() << key << " = " << bad << " passed";
			}
			catch (const std::invalid_argument& e)
			{
				EXPECT_NE(std::string(e.what()).find(key), std::string::npos)
				    << e.what();
			}
		}
}
