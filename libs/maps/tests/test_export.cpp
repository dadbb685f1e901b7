// Static (ghost-free) map export: PLY and OctoMap .bt, and the drawing.
#include <bims/maps/export.h>
#include <bims/maps/motion_grids.h>

#include <mrpt/opengl/COctoMapVoxels.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/system/filesystem.h>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <cstdio>
#include <fstream>

#include <bims_test/file_size_limit.h>

#include "scene_raycaster.h"
#include "test_util.h"

using namespace bims::maps;
using namespace bims::maps::test;

namespace
{
// Static room seen for a few frames, then a box moving through it.
MotionGrids& scenario()
{
	static MotionGrids mg(
	    []
	    {
		    GridParams p = test::paperGrids();
		    p.decay = DecayMode::Raycast;
		    p.voxel_size = 0.1;
		    return p;
	    }());
	if (mg.occupancy()->frameCount() > 0) return mg;
	const auto scene = room();
	const mrpt::poses::CPose3D T(-2, 0, 1.2, 0, 0, 0);
	for (int f = 0; f < 10; ++f)
	{
		auto s = scene;
		if (f >= 6)
			s.push_back({{0.5, -1.0 + 0.3 * (f - 6), 0.5},
			             {0.8, -0.6 + 0.3 * (f - 6), 1.6}});
		mg.processFrame(*renderScan(s, T, 96, 72, 70, f), T, nullptr);
	}
	return mg;
}

std::string tmpPath(const std::string& name)
{
	return mrpt::system::getTempFileName() + "_" + name;
}
}  // namespace

TEST(Export, StaticMapExcludesMovingVoxels)
{
	auto& mg = scenario();
	const auto all = staticOccupiedKeys(*mg.occupancy(), nullptr);
	const auto stat =
	    staticOccupiedKeys(*mg.occupancy(), mg.flowConsistency().get());
	ASSERT_GT(mg.flowConsistency()->movingCells().size(), 5u);
	EXPECT_LT(stat.size(), all.size());
	// No voxel of the box region in the static map.
	for (const auto& k : stat)
	{
		const auto c = mg.occupancy()->centerOf(k);
		const bool inBoxPath = c.x > 0.45 && c.x < 0.85 && c.z > 0.5 &&
		                       c.z < 1.6 && c.y > -1.05 && c.y < 0.35;
		EXPECT_FALSE(inBoxPath) << c.x << " " << c.y << " " << c.z;
	}
}

TEST(Export, VoxelSetsCarryTheirGridsProbabilities)
{
	auto& mg = scenario();
	const auto& occ = *mg.occupancy();
	const auto* motion = mg.flowConsistency().get();
	const VoxelSet all = occupiedVoxels(occ, 0.5),
	               stat = staticVoxels(occ, motion);
	ASSERT_EQ(all.size(), staticOccupiedKeys(occ, nullptr).size());
	ASSERT_EQ(stat.size(), staticOccupiedKeys(occ, motion).size());
	ASSERT_EQ(all.probabilities.size(), all.size());
	for (size_t i = 0; i < all.size(); ++i)
	{
		EXPECT_GT(all.probabilities[i], 0.5f);
		EXPECT_NEAR(all.probabilities[i], occ.probabilityAt(all.centres[i]),
		            1e-6);
	}
	EXPECT_LT(occupiedVoxels(occ, 0.9).size(), all.size());
	// the last frame's moving voxels: movingCells() with their P(I)
	const VoxelSet moving = movingVoxels(*motion);
	const auto centres = motion->movingCells();
	ASSERT_GT(moving.size(), 5u);
	ASSERT_EQ(moving.size(), centres.size());
	for (size_t i = 0; i < moving.size(); ++i)
	{
		EXPECT_EQ(moving.centres[i], centres[i]);
		EXPECT_GT(moving.probabilities[i], 0.5f);
		EXPECT_NEAR(moving.probabilities[i],
		            motion->probabilityAt(centres[i]).value(), 1e-6);
	}
}

TEST(Export, PlyHeaderAndSize)
{
	auto& mg = scenario();
	const auto path = tmpPath("static.ply");
	const size_t n =
	    writeStaticPly(path, *mg.occupancy(), mg.flowConsistency().get());
	std::ifstream f(path, std::ios::binary);
	std::string line, header;
	while (std::getline(f, line) && line != "end_header") header += line + "\n";
	EXPECT_NE(header.find("format binary_little_endian 1.0"),
	          std::string::npos);
	EXPECT_NE(header.find("element vertex " + std::to_string(n)),
	          std::string::npos);
	const auto pos = f.tellg();
	f.seekg(0, std::ios::end);
	EXPECT_EQ(size_t(f.tellg() - pos), n * 16);
	EXPECT_THROW(
	    writeStaticPly("/nonexistent_dir/x.ply", *mg.occupancy(), nullptr),
	    std::runtime_error);
}

TEST(Export, OctomapBtReadsBackWithTheSameOccupiedVoxels)
{
	auto& mg = scenario();
	const auto path = tmpPath("static.bt");
	testing::internal::CaptureStderr();
	const size_t n =
	    writeStaticOctomap(path, *mg.occupancy(), mg.flowConsistency().get());
	// (liboctomap's own writer prints " done." there)
	EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
	ASSERT_GT(n, 100u);
	octomap::OcTree tree(0.1);
	ASSERT_TRUE(tree.readBinary(path));
	EXPECT_NEAR(tree.getResolution(), 0.1, 1e-9);
	size_t occ = 0;
	for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it)
		if (tree.isNodeOccupied(*it))
			occ += size_t(1) << (3 * (tree.getTreeDepth() - it.getDepth()));
	EXPECT_EQ(occ, n);
	for (const auto& k :
	     staticOccupiedKeys(*mg.occupancy(), mg.flowConsistency().get()))
	{
		const auto c = mg.occupancy()->centerOf(k);
		auto* node = tree.search(c.x, c.y, c.z);
		ASSERT_NE(node, nullptr);
		EXPECT_TRUE(tree.isNodeOccupied(node));
	}
}

TEST(Export, VisualisationUsesThePaperColours)
{
	auto& mg = scenario();
	mrpt::opengl::CSetOfObjects o0, o1, o2;
	mg.occupancy()->getVisualizationInto(o0);
	mg.background()->getVisualizationInto(o1);
	mg.flowConsistency()->getVisualizationInto(o2);
	auto colourOf = [](const mrpt::opengl::CSetOfObjects& o)
	{
		auto v = o.getByClass<mrpt::opengl::COctoMapVoxels>();
		EXPECT_TRUE(v);
		EXPECT_GT(v->getVoxelCount(0), 0u);
		return v->getVoxel(0, 0).color;
	};
	EXPECT_EQ(colourOf(o0), mrpt::img::TColor(0, 0, 255, 255));
	EXPECT_EQ(colourOf(o1), mrpt::img::TColor(255, 255, 0, 255));
	EXPECT_EQ(colourOf(o2), mrpt::img::TColor(255, 0, 0, 255));
}

TEST(Export, APlyWriteThatFailsOnlyAtCloseIsAnError)
{
	// 200 points (3.4 kB, all in the stream's buffer until it is closed) in
	// a child limited to 1000-byte files (SIGXFSZ ignored: the write fails
	// with EFBIG, as on a full disk): the failure comes at close and must
	// not pass silently
	const std::string path =
	    mrpt::system::getTempFileName() + "_close_limit.ply";
	const int code = bims::test::exitOfChildWithFileSizeLimit(
	    1000,
	    [&]
	    {
		    try
		    {
			    writePointsPly(
			        path, std::vector<mrpt::math::TPoint3D>(200, {1, 2, 3}),
			        std::vector<float>(200, 0.5f));
			    return 0;
		    }
		    catch (const std::exception& e)
		    {
			    const std::string m = e.what();
			    return m.find("error writing PLY file") != std::string::npos
			               ? 3
			               : 4;
		    }
	    });
	std::remove(path.c_str());
	EXPECT_EQ(code, 3);
}
