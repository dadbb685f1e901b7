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

size_t writeStaticPly(const std::string& path, const COccupancyBayesGrid& occ,
                      const CMotionGridBase* motion, double p)
{
	const auto keys = staticOccupiedKeys(occ, motion, p);
	std::vector<mrpt::math::TPoint3D> pts;
	std::vector<float> probs;
	pts.reserve(keys.size());
	for (const auto& k : keys)
	{
		pts.push_back(occ.centerOf(k));
		probs.push_back(float(sigmoid(fromFixed(occ.logOddsFixed(k)))));
	}
	writePointsPly(path, pts, probs);
	return pts.size();
}

}  // namespace bims::maps
