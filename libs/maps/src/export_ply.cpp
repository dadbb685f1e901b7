#include <bims/maps/closed_form.h>
#include <bims/maps/export.h>

#include <cstring>
#include <fstream>
#include <stdexcept>

namespace bims::maps
{
std::vector<VoxelKey> staticOccupiedKeys(const COccupancyBayesGrid& occ,
                                         const CMotionGridBase* motion,
                                         double p)
{
	if (motion && motion->params().voxel_size != occ.params().voxel_size)
		throw std::invalid_argument(
		    "staticOccupiedKeys: tier-0 and motion grids differ in voxel size");
	std::vector<VoxelKey> out;
	for (const auto& k : occ.keysAbove(p))
		if (!motion || !motion->wasMovingAtLastHit(k)) out.push_back(k);
	return out;
}

void writePointsPly(const std::string& path,
                    const std::vector<mrpt::math::TPoint3D>& pts,
                    const std::vector<float>& values)
{
	if (values.size() != pts.size())
		throw std::invalid_argument("writePointsPly: one value per point");
	std::ofstream f(path, std::ios::binary);
	if (!f) throw std::runtime_error("cannot write PLY file '" + path + "'");
	f << "ply\nformat binary_little_endian 1.0\n"
	  << "comment bims static voxel map: voxel centres in {W} [m]\n"
	  << "element vertex " << pts.size() << "\n"
	  << "property float x\nproperty float y\nproperty float z\n"
	  << "property float value\nend_header\n";
	static_assert(sizeof(float) == 4);
	for (size_t i = 0; i < pts.size(); ++i)
	{
		const float v[4] = {float(pts[i].x), float(pts[i].y), float(pts[i].z),
		                    values[i]};
		unsigned char b[16];
		std::memcpy(b, v, 16);  // x86/ARM little endian hosts
		f.write(reinterpret_cast<const char*>(b), 16);
	}
	f.close();  // (the last bytes reach the file here: checked too)
	if (!f) throw std::runtime_error("error writing PLY file '" + path + "'");
}

VoxelSet staticVoxels(const COccupancyBayesGrid& occ,
                      const CMotionGridBase* motion, double p)
{
	VoxelSet out;
	const auto keys = staticOccupiedKeys(occ, motion, p);
	out.centres.reserve(keys.size());
	out.probabilities.reserve(keys.size());
	for (const auto& k : keys)
	{
		out.centres.push_back(occ.centerOf(k));
		out.probabilities.push_back(
		    float(sigmoid(fromFixed(occ.logOddsFixed(k)))));
	}
	return out;
}

VoxelSet occupiedVoxels(const COccupancyBayesGrid& occ, double p)
{
	return staticVoxels(occ, nullptr, p);
}

VoxelSet movingVoxels(const CMotionGridBase& motion)
{
	VoxelSet out;
	motion.forEachMovingCell(
	    [&](const VoxelKey& k, float post)
	    {
		    out.centres.push_back(motion.centerOf(k));
		    out.probabilities.push_back(float(sigmoid(post)));
	    });
	return out;
}

size_t writeStaticPly(const std::string& path, const COccupancyBayesGrid& occ,
                      const CMotionGridBase* motion, double p)
{
	const VoxelSet v = staticVoxels(occ, motion, p);
	writePointsPly(path, v.centres, v.probabilities);
	return v.size();
}

}  // namespace bims::maps
