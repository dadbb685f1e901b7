// Tiers 1 and 2: registration, map definitions, serialisation, drawing.
#include <bims/maps/CMotionGridBase.h>

#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/serialization/CArchive.h>

#include "internal.h"

namespace bims::maps
{
MAP_DEFINITION_REGISTER(
    "bims::maps::CBackgroundSubtractionGrid,backgroundSubtractionGrid",
    bims::maps::CBackgroundSubtractionGrid)
MAP_DEFINITION_REGISTER("bims::maps::CFlowConsistencyGrid,flowConsistencyGrid",
                        bims::maps::CFlowConsistencyGrid)

IMPLEMENTS_SERIALIZABLE(CBackgroundSubtractionGrid, CMotionGridBase, bims::maps)
IMPLEMENTS_SERIALIZABLE(CFlowConsistencyGrid, CMotionGridBase, bims::maps)

CBackgroundSubtractionGrid::TMapDefinition::TMapDefinition() = default;
void CBackgroundSubtractionGrid::TMapDefinition::
    loadFromConfigFile_map_specific(const mrpt::config::CConfigFileBase& source,
                                    const std::string& prefix)
{
	params.loadFromConfigFile(source, prefix + "_creationOpts",
	                          mrptGenericMapKeys());
}
void CBackgroundSubtractionGrid::TMapDefinition::dumpToTextStream_map_specific(
    std::ostream& out) const
{
	params.dump(out);
}
mrpt::maps::CMetricMap*
CBackgroundSubtractionGrid::internal_CreateFromMapDefinition(
    const mrpt::maps::TMetricMapInitializer& def)
{
	const auto& d =
	    dynamic_cast<const CBackgroundSubtractionGrid::TMapDefinition&>(def);
	return new CBackgroundSubtractionGrid(d.params);
}

CFlowConsistencyGrid::TMapDefinition::TMapDefinition() = default;
void CFlowConsistencyGrid::TMapDefinition::loadFromConfigFile_map_specific(
    const mrpt::config::CConfigFileBase& source, const std::string& prefix)
{
	params.loadFromConfigFile(source, prefix + "_creationOpts",
	                          mrptGenericMapKeys());
}
void CFlowConsistencyGrid::TMapDefinition::dumpToTextStream_map_specific(
    std::ostream& out) const
{
	params.dump(out);
}
mrpt::maps::CMetricMap* CFlowConsistencyGrid::internal_CreateFromMapDefinition(
    const mrpt::maps::TMetricMapInitializer& def)
{
	const auto& d =
	    dynamic_cast<const CFlowConsistencyGrid::TMapDefinition&>(def);
	return new CFlowConsistencyGrid(d.params);
}

uint8_t CBackgroundSubtractionGrid::serializeGetVersion() const
{
	return kSerializationVersion;
}
void CBackgroundSubtractionGrid::serializeTo(
    mrpt::serialization::CArchive& out) const
{
	writeMotion(out);
}
void CBackgroundSubtractionGrid::serializeFrom(
    mrpt::serialization::CArchive& in, uint8_t version)
{
	if (version > kSerializationVersion)
		MRPT_THROW_UNKNOWN_SERIALIZATION_VERSION(version);
	readMotion(in, version);
}

uint8_t CFlowConsistencyGrid::serializeGetVersion() const
{
	return kSerializationVersion;
}
void CFlowConsistencyGrid::serializeTo(mrpt::serialization::CArchive& out) const
{
	writeMotion(out);
}
void CFlowConsistencyGrid::serializeFrom(mrpt::serialization::CArchive& in,
                                         uint8_t version)
{
	if (version > kSerializationVersion)
		MRPT_THROW_UNKNOWN_SERIALIZATION_VERSION(version);
	readMotion(in, version);
}

// Colours of the paper's Fig. 4: tier 1 yellow, tier 2 red.
void CBackgroundSubtractionGrid::getVisualizationInto(
    mrpt::opengl::CSetOfObjects& o) const
{
	visualize(o, mrpt::img::TColor(255, 255, 0, 255), "tier1_background");
}
void CFlowConsistencyGrid::getVisualizationInto(
    mrpt::opengl::CSetOfObjects& o) const
{
	visualize(o, mrpt::img::TColor(255, 0, 0, 255), "tier2_flow");
}

}  // namespace bims::maps
