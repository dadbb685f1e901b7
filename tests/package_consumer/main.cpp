// bims's voxel grids in a program of its own, through MRPT's interfaces only
// (no bims symbol named: the grids must have registered themselves with
// MRPT, which the whole-archive link of bims::maps ensures): a
// COccupancyBayesGrid created from an .ini by mrpt::maps::CMultiMetricMap,
// one synthetic depth image inserted, its occupied voxels (P(O) > 0.5, as
// its 3D view draws them) counted.
//   grid_from_ini GRID.ini   (exit code 0 if the grid holds occupied voxels)
#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/opengl/COctoMapVoxels.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/poses/CPose3D.h>

#include <cstdio>
#include <exception>
#include <string>

namespace
{
/** A 64x48 depth image of a wall 2 m in front of the camera. */
mrpt::obs::CObservation3DRangeScan::Ptr wall()
{
	auto o = mrpt::obs::CObservation3DRangeScan::Create();
	o->hasRangeImage = true;
	o->range_is_depth = true;
	o->rangeUnits = 0.001f;  // uint16 mm
	o->rangeImage_setSize(48, 64);
	o->rangeImage.fill(2000);
	o->cameraParams.ncols = 64;
	o->cameraParams.nrows = 48;
	o->cameraParams.setIntrinsicParamsFromValues(60, 60, 31.5, 23.5);
	o->timestamp = mrpt::Clock::now();
	return o;
}
}  // namespace

int main(int argc, char** argv)
{
	if (argc != 2)
	{
		std::fprintf(stderr, "usage: %s GRID.ini\n", argv[0]);
		return 2;
	}
	try
	{
		mrpt::config::CConfigFile ini(argv[1]);
		mrpt::maps::TSetOfMetricMapInitializers inits;
		inits.loadFromConfigFile(ini, "map");
		mrpt::maps::CMultiMetricMap maps(inits);
		const std::string name = "bims::maps::COccupancyBayesGrid";
		mrpt::maps::CMetricMap::Ptr grid;
		for (const auto& m : maps.maps)
			if (m->GetRuntimeClass()->className == name) grid = m;
		if (!grid)
		{
			std::fprintf(stderr, "no %s made from %s\n", name.c_str(), argv[1]);
			return 1;
		}
		// camera 1 m above the origin, looking along x
		maps.insertObservation(*wall(), mrpt::poses::CPose3D(0, 0, 1, 0, 0, 0));

		mrpt::opengl::CSetOfObjects view;
		grid->getVisualizationInto(view);
		const auto voxels =
		    view.getByClass<mrpt::opengl::COctoMapVoxels>();  // tier 0
		const size_t occupied = voxels ? voxels->getVoxelCount(0) : 0;
		std::printf("%s: %zu occupied voxels\n", name.c_str(), occupied);
		return occupied > 0 ? 0 : 1;
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "error: %s\n", e.what());
		return 1;
	}
}
