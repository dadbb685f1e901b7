// Tier 0: registration, map definition, serialisation, visualisation.
#include <bims/maps/COccupancyBayesGrid.h>
#include <bims/maps/export.h>

#include "internal.h"

#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/serialization/CArchive.h>

#include <sstream>

namespace bims::maps
{
// Names usable as "<name>_count" under [map]; must contain the RTTI name.
MAP_DEFINITION_REGISTER("bims::maps::COccupancyBayesGrid,occupancyBayesGrid",
                        bims::maps::COccupancyBayesGrid)

IMPLEMENTS_SERIALIZABLE(COccupancyBayesGrid, CBayesVoxelGridBase, bims::maps)

const std::vector<std::string>& mrptGenericMapKeys()
{
	static const std::vector<std::string> k = {"enableSaveAs3DObject",
	                                           "enableObservationLikelihood",
	                                           "enableObservationInsertion"};
	return k;
}

COccupancyBayesGrid::TMapDefinition::TMapDefinition() = default;

void COccupancyBayesGrid::TMapDefinition::loadFromConfigFile_map_specific(
    const mrpt::config::CConfigFileBase& source, const std::string& prefix)
{
	params.loadFromConfigFile(source, prefix + "_creationOpts",
	                          mrptGenericMapKeys());
}

void COccupancyBayesGrid::TMapDefinition::dumpToTextStream_map_specific(
    std::ostream& out) const
{
	params.dump(out);
}

mrpt::maps::CMetricMap* COccupancyBayesGrid::internal_CreateFromMapDefinition(
    const mrpt::maps::TMetricMapInitializer& def)
{
	const auto& d =
	    dynamic_cast<const COccupancyBayesGrid::TMapDefinition&>(def);
	return new COccupancyBayesGrid(d.params);
}

uint8_t COccupancyBayesGrid::serializeGetVersion() const
{
	return 4;  // = readBase's layout of the parameters (4: key = value rows)
}

void COccupancyBayesGrid::serializeTo(mrpt::serialization::CArchive& out) const
{
	writeBase(out);
	const uint64_t nb = grid_.numBlocks();
	out << nb;
	constexpr size_t N = Storage::kCellsPerBlock;
	std::vector<int32_t> l(N), lp(N);
	std::vector<uint32_t> st(N);
	for (size_t b = 0; b < nb; ++b)
	{
		const auto& blk = grid_.block(b);
		for (size_t c = 0; c < N; ++c)
		{
			l[c] = blk.cells[c].l;
			lp[c] = blk.cells[c].lPrev;
			st[c] = blk.cells[c].stamp;
		}
		out << grid_.blockKey(b);
		out.WriteBufferFixEndianness(l.data(), N);
		out.WriteBufferFixEndianness(lp.data(), N);
		out.WriteBufferFixEndianness(st.data(), N);
	}
}

void COccupancyBayesGrid::serializeFrom(mrpt::serialization::CArchive& in,
                                        uint8_t version)
{
	if (version > 4) MRPT_THROW_UNKNOWN_SERIALIZATION_VERSION(version);
	grid_.clear();
	readBase(in, version);
	grid_.setMaxBytes(size_t(params_.max_memory_mb * 1048576.0));
	updateConstants();
	uint64_t nb;
	in >> nb;
	constexpr size_t N = Storage::kCellsPerBlock;
	std::vector<int32_t> l(N), lp(N);
	std::vector<uint32_t> st(N);
	for (uint64_t b = 0; b < nb; ++b)
	{
		uint64_t key;
		in >> key;
		in.ReadBufferFixEndianness(l.data(), N);
		in.ReadBufferFixEndianness(lp.data(), N);
		in.ReadBufferFixEndianness(st.data(), N);
		const uint32_t id = grid_.findOrCreateBlock(key);
		if (id == FlatHashMap::kNotFound)
			throw std::runtime_error(
			    "COccupancyBayesGrid: serialised map exceeds max_memory_mb");
		auto& blk = grid_.block(id);
		for (size_t c = 0; c < N; ++c)
		{
			if (st[c] > frameCount_)
				throw std::runtime_error(
				    "COccupancyBayesGrid: corrupt serialised map (cell stamp "
				    "beyond frame count)");
			blk.cells[c] = {l[c], lp[c], st[c]};
		}
	}
}

void COccupancyBayesGrid::getVisualizationInto(
    mrpt::opengl::CSetOfObjects& o) const
{
	if (!genericMapParams.enableSaveAs3DObject) return;
	// Tier 0 in blue (the paper's Fig. 4): voxels with P(O) > 0.5.
	addVoxelsTo(o, cellsAbove(0.5), mrpt::img::TColor(0, 0, 255, 255),
	            "tier0_occupancy");
}

std::string COccupancyBayesGrid::asString() const
{
	std::ostringstream s;
	s << "COccupancyBayesGrid (tier 0): voxel " << params_.voxel_size
	  << " m, decay=" << choiceName(params_.decay) << ", " << frameCount_
	  << " frames, " << grid_.numBlocks() << " blocks, "
	  << grid_.memoryBytes() / 1048576.0 << " MiB";
	return s.str();
}

void COccupancyBayesGrid::saveMetricMapRepresentationToFile(
    const std::string& prefix) const
{
	writeStaticPly(prefix + "_occupied.ply", *this, nullptr);
}

}  // namespace bims::maps
