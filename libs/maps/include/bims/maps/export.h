// Export of the static map without moving objects ("ghost-free" map).
#pragma once

#include <bims/maps/CMotionGridBase.h>

#include <string>
#include <vector>

namespace bims::maps
{
/** Voxels as their centres [m, {W}] with one probability each (occupancy
 * for tier 0, P(I) for a motion tier): what the exports write and the
 * Python module returns. */
struct VoxelSet
{
	std::vector<mrpt::math::TPoint3D> centres;
	std::vector<float> probabilities;
	size_t size() const { return centres.size(); }
};

/** Tier-0 voxels with occupancy probability > \a pOccupied. */
VoxelSet occupiedVoxels(const COccupancyBayesGrid& occupancy,
                        double pOccupied = 0.5);

/** The last frame's voxels that \a motion labels moving (MAP), with their
 * posterior P(I). */
VoxelSet movingVoxels(const CMotionGridBase& motion);

/** Voxels of the static map: tier-0 voxels with probability > \a pOccupied
 * that \a motion (tier 1 or 2; may be null) did not label moving at their
 * last hit. */
std::vector<VoxelKey> staticOccupiedKeys(const COccupancyBayesGrid& occupancy,
                                         const CMotionGridBase* motion,
                                         double pOccupied = 0.5);
/** staticOccupiedKeys() as centres with their occupancy probability. */
VoxelSet staticVoxels(const COccupancyBayesGrid& occupancy,
                      const CMotionGridBase* motion, double pOccupied = 0.5);

/** Writes voxel centres [m, {W}] as a binary little-endian PLY point cloud
 * (float x y z, float occupancy probability). Returns the number of
 * vertices. Throws std::runtime_error naming the file on I/O failure. */
size_t writeStaticPly(const std::string& path,
                      const COccupancyBayesGrid& occupancy,
                      const CMotionGridBase* motion, double pOccupied = 0.5);

/** Writes points [m] with a per-point value as a binary little-endian PLY
 * (float x y z, float value). Throws std::runtime_error naming the file. */
void writePointsPly(const std::string& path,
                    const std::vector<mrpt::math::TPoint3D>& pts,
                    const std::vector<float>& values);

/** Writes the static map as an OctoMap binary tree (.bt) at the grid's
 * resolution (occupied voxels only; free space is not written), readable
 * by octovis and octomap::OcTree::readBinary. Returns the number of
 * occupied leaves written. Throws std::runtime_error naming the file. */
size_t writeStaticOctomap(const std::string& path,
                          const COccupancyBayesGrid& occupancy,
                          const CMotionGridBase* motion,
                          double pOccupied = 0.5);

}  // namespace bims::maps
