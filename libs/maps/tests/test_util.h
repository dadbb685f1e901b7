// Helpers shared by the maps tests.
#pragma once

#include <bims/maps/frame_cloud.h>
#include <bims_test/presets.h>

#include <vector>

namespace bims::maps::test
{
/** The paper's literal model (config/paper.ini [grids]), which these tests
 * were written against: the built-in defaults are config/default.ini's. */
inline GridParams paperGrids()
{
	return bims::test::paperPreset<GridParams>("grids");
}

/** A frame with \a counts[i] readings at the centre of voxel keys[i], seen
 * from \a origin (an unorganised cloud, no intrinsics). */
inline FrameCloud frameAt(const GridParams& p,
                          const std::vector<VoxelKey>& keys,
                          const std::vector<uint32_t>& counts,
                          const mrpt::math::TPoint3D& origin = {0, 0, 0},
                          int stamp = 0)
{
	std::vector<mrpt::math::TPoint3Df> pts;
	const double s = p.voxel_size;
	for (size_t i = 0; i < keys.size(); ++i)
		for (uint32_t j = 0; j < counts[i]; ++j)
			pts.emplace_back(float((keys[i].x + 0.5) * s),
			                 float((keys[i].y + 0.5) * s),
			                 float((keys[i].z + 0.5) * s));
	FrameCloud f;
	FrameCloudBuilder b(p);
	b.buildFromPoints(pts, {}, origin, f);
	f.timestamp = mrpt::Clock::time_point(mrpt::Clock::duration(stamp));
	return f;
}
}  // namespace bims::maps::test
