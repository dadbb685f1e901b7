// .bt export through liboctomap (the same library MRPT's maps module links,
// so there is no duplicate-symbol clash; see docs/maps.md).
#include <bims/maps/closed_form.h>
#include <bims/maps/export.h>

#include <octomap/OcTree.h>

#include <fstream>
#include <stdexcept>

namespace bims::maps
{
namespace
{
/** An OcTree written as OcTree::writeBinary writes it (pruned maximum
 * likelihood tree: the .bt header lines, then the binary data), without the
 * " done." line Debian's liboctomap prints on stderr after each write. */
class QuietOcTree : public octomap::OcTree
{
 public:
	using octomap::OcTree::OcTree;
	bool writeBinaryQuietly(const std::string& path)
	{
		toMaxLikelihood();
		prune();
		std::ofstream f(path, std::ios::binary);
		if (!f) return false;
		f << binaryFileHeader
		  << "\n# static map without moving objects, bims\n#\n"
		  << "id " << getTreeType() << "\n"
		  << "size " << size() << "\n"
		  << "res " << getResolution() << "\n"
		  << "data\n";
		writeBinaryData(f);
		f.close();
		return !f.fail();
	}
};
}  // namespace

size_t writeStaticOctomap(const std::string& path,
                          const COccupancyBayesGrid& occ,
                          const CMotionGridBase* motion, double p)
{
	const auto keys = staticOccupiedKeys(occ, motion, p);
	QuietOcTree tree(occ.params().voxel_size);
	size_t n = 0;
	for (const auto& k : keys)
	{
		const auto c = occ.centerOf(k);
		octomap::OcTreeKey ok;
		if (!tree.coordToKeyChecked(
		        octomap::point3d(float(c.x), float(c.y), float(c.z)), ok))
			continue;  // outside OctoMap's +-2^15 voxel range
		tree.setNodeValue(ok, float(fromFixed(occ.logOddsFixed(k))), true);
		++n;
	}
	tree.updateInnerOccupancy();
	if (!tree.writeBinaryQuietly(path))
		throw std::runtime_error("cannot write OctoMap file '" + path + "'");
	return n;
}

}  // namespace bims::maps
