#include <bims/common/config.h>
#include <bims/common/options.h>
#include <bims/maps/CBayesVoxelGridBase.h>
#include <bims/maps/register.h>

#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/opengl/COctoMapVoxels.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/serialization/CArchive.h>

#include <string>

namespace bims::maps
{
IMPLEMENTS_VIRTUAL_SERIALIZABLE(CBayesVoxelGridBase, mrpt::maps::CMetricMap,
                                bims::maps)

CBayesVoxelGridBase::CBayesVoxelGridBase(const GridParams& p)
    : params_(p), builder_(p)
{
	registerClasses();
	params_.validate();
}

void CBayesVoxelGridBase::setParamsBase(const GridParams& p)
{
	p.validate();
	params_ = p;
	builder_.setParams(p);
}

void CBayesVoxelGridBase::clearBase()
{
	frameCount_ = 0;
	lastTimestamp_ = {};
	totalStats_ = {};
	badPoseFrames_ = 0;
}

VoxelKey CBayesVoxelGridBase::keyOf(const mrpt::math::TPoint3D& p) const
{
	const double inv = 1 / params_.voxel_size;
	return {coordToIndex(p.x, inv), coordToIndex(p.y, inv),
	        coordToIndex(p.z, inv)};
}

mrpt::math::TPoint3D CBayesVoxelGridBase::centerOf(const VoxelKey& k) const
{
	const double s = params_.voxel_size;
	return {(k.x + 0.5) * s, (k.y + 0.5) * s, (k.z + 0.5) * s};
}

bool CBayesVoxelGridBase::buildFrame(
    const mrpt::obs::CObservation3DRangeScan& scan,
    const mrpt::poses::CPose3D& robotPose, FrameCloud& out) const
{
	builder_.build(scan, robotPose + scan.sensorPose, out);
	accountFrame(out.stats);
	return !out.stats.badPose;
}

bool CBayesVoxelGridBase::buildFrameOf(
    const mrpt::obs::CObservation& obs,
    const std::optional<const mrpt::poses::CPose3D>& robotPose,
    FrameCloud& out) const
{
	const auto* scan =
	    dynamic_cast<const mrpt::obs::CObservation3DRangeScan*>(&obs);
	return scan &&
	       buildFrame(*scan, robotPose ? *robotPose : mrpt::poses::CPose3D(),
	                  out);
}

void CBayesVoxelGridBase::accountFrame(const FrameStats& s) const
{
	totalStats_ += s;
	if (s.badPose) badPoseFrames_++;
	const struct
	{
		size_t n;
		const char* what;
	} reasons[] = {
	    {s.badPose ? 1u : 0u, "a frame with a non-finite pose was skipped"},
	    {s.nonFinite, "readings with NaN/inf coordinates were skipped"},
	    {s.outsideExtent,
	     "readings outside the configured extent were skipped"},
	    {s.overBudget,
	     "cells beyond the memory budget (max_memory_mb) were not created"}};
	for (unsigned i = 0; i < 4; ++i)
	{
		if (reasons[i].n == 0 || (warned_ & (1u << i))) continue;
		warned_ |= 1u << i;
		reportWarning(warn_,
		              {Warning::Kind::Warning, GetRuntimeClass()->className,
		               std::string(reasons[i].what) + " (" +
		                   std::to_string(reasons[i].n) +
		                   " in this frame; totals in totalStats(), "
		                   "warned once)"});
	}
}

double CBayesVoxelGridBase::internal_computeObservationLikelihood(
    const mrpt::obs::CObservation&, const mrpt::poses::CPose3D&) const
{
	return 0;
}
bool CBayesVoxelGridBase::internal_canComputeObservationLikelihood(
    const mrpt::obs::CObservation&) const
{
	return false;
}

void CBayesVoxelGridBase::writeBase(mrpt::serialization::CArchive& out,
                                    uint8_t version) const
{
	const auto& p = params_;
	if (version >= 4)
	{
		// The parameters as their describe() names them: a new key needs
		// no new layout (readBase).
		const auto rows = optionRows(p);
		out << uint32_t(rows.size());
		for (const auto& r : rows) out << r.key << r.value;
		out << frameCount_
		    << int64_t(lastTimestamp_.time_since_epoch().count());
		return;
	}
	out << p.voxel_size << uint8_t(p.decay) << p.p_miss << p.reading_lambda
	    << p.p_min << p.p_max << p.bg_transition_eps << p.flow_transition_tau
	    << p.flow_lambda << uint8_t(p.flow_evidence) << p.max_range << p.extent
	    << p.max_memory_mb << int32_t(p.raycast_decimation)
	    << uint8_t(p.raycast_target);
	if (version >= 1)
		out << p.p_unknown << uint8_t(p.bg_neighbourhood) << p.exclude_moving;
	if (version >= 2) out << uint8_t(p.exclude_by);
	if (version >= 3) out << p.raycast_margin;
	out << frameCount_ << int64_t(lastTimestamp_.time_since_epoch().count());
}

void CBayesVoxelGridBase::readBase(mrpt::serialization::CArchive& in,
                                   uint8_t version)
{
	// Keys a version does not hold were not options yet: the map was
	// built with the paper's model there (config/paper.ini), whatever the
	// defaults are now.
	GridParams p;
	if (version >= 4)
		p = readParamRows(in);
	else
		p = readParamsBinary(in, version);
	setParamsBase(p);  // validates
	int64_t ts;
	in >> frameCount_ >> ts;
	lastTimestamp_ = mrpt::Clock::time_point(mrpt::Clock::duration(ts));
	totalStats_ = {};
	badPoseFrames_ = 0;
}

GridParams CBayesVoxelGridBase::readParamRows(mrpt::serialization::CArchive& in)
{
	// key = value rows read as a [grids] section is: unknown keys, values
	// out of range and bad choices are errors. A key the stream lacks (a map
	// written before the key existed) keeps its default, which must then
	// give the model as it was before the key (docs/maps.md).
	uint32_t n = 0;
	in >> n;
	if (n > 1000)
		throw std::runtime_error("bims::maps: corrupt serialised grid (" +
		                         std::to_string(n) + " parameters)");
	std::string ini = "[grids]\n", key, value;
	for (uint32_t i = 0; i < n; ++i)
	{
		in >> key >> value;
		if (key.empty() || key.find_first_of("=\n\r[]") != std::string::npos ||
		    value.find_first_of("\n\r") != std::string::npos)
			throw std::runtime_error(
			    "bims::maps: corrupt serialised grid (parameter row " +
			    std::to_string(i) + ")");
		ini += key + "=" + value + "\n";
	}
	GridParams p;
	try
	{
		p.loadFromConfigFile(mrpt::config::CConfigFileMemory(ini), "grids");
	}
	catch (const ConfigError& e)
	{
		throw std::runtime_error(
		    std::string("bims::maps: corrupt serialised grid (") + e.what() +
		    ")");
	}
	p.raycast_threads = 1;  // the reading machine's choice, not the map's
	return p;
}

GridParams CBayesVoxelGridBase::readParamsBinary(
    mrpt::serialization::CArchive& in, uint8_t version)
{
	GridParams p;
	p.raycast_margin = 0;
	p.p_unknown = 0;
	p.bg_neighbourhood = BgNeighbourhood::None;
	p.exclude_moving = false;
	p.exclude_by = ExcludeBy::Decision;
	uint8_t decay, ev, tgt;
	int32_t dec;
	in >> p.voxel_size >> decay >> p.p_miss >> p.reading_lambda >> p.p_min >>
	    p.p_max >> p.bg_transition_eps >> p.flow_transition_tau >>
	    p.flow_lambda >> ev >> p.max_range >> p.extent >> p.max_memory_mb >>
	    dec >> tgt;
	if (decay > 2 || ev > 1 || tgt > 1)
		throw std::runtime_error(
		    "bims::maps: corrupt serialised grid (bad enum value)");
	p.decay = DecayMode(decay);
	p.flow_evidence = FlowEvidence(ev);
	p.raycast_target = RayTarget(tgt);
	p.raycast_decimation = dec;
	if (version >= 1)
	{
		uint8_t nb;
		in >> p.p_unknown >> nb >> p.exclude_moving;
		if (nb > 3)
			throw std::runtime_error(
			    "bims::maps: corrupt serialised grid (bad enum value)");
		p.bg_neighbourhood = BgNeighbourhood(nb);
	}
	if (version >= 2)
	{
		uint8_t xb;
		in >> xb;
		if (xb > 2)
			throw std::runtime_error(
			    "bims::maps: corrupt serialised grid (bad enum value)");
		p.exclude_by = ExcludeBy(xb);
	}
	if (version >= 3) in >> p.raycast_margin;
	return p;
}

void CBayesVoxelGridBase::addVoxelsTo(
    mrpt::opengl::CSetOfObjects& o,
    const std::vector<mrpt::math::TPoint3D>& centers,
    const mrpt::img::TColor& color, const std::string& name) const
{
	auto vox = mrpt::opengl::COctoMapVoxels::Create();
	vox->setName(name);
	vox->resizeVoxelSets(1);
	vox->reserveVoxels(0, centers.size());
	mrpt::math::TPoint3D lo(1e9, 1e9, 1e9), hi(-1e9, -1e9, -1e9);
	for (const auto& c : centers)
	{
		vox->push_back_Voxel(0, mrpt::opengl::COctoMapVoxels::TVoxel(
		                            c, params_.voxel_size, color));
		lo.x = std::min(lo.x, c.x);
		lo.y = std::min(lo.y, c.y);
		lo.z = std::min(lo.z, c.z);
		hi.x = std::max(hi.x, c.x);
		hi.y = std::max(hi.y, c.y);
		hi.z = std::max(hi.z, c.z);
	}
	if (!centers.empty()) vox->setBoundingBox(lo, hi);
	vox->setVisualizationMode(mrpt::opengl::COctoMapVoxels::FIXED);
	vox->showGridLines(false);
	vox->enableCubeTransparency(color.A < 255);
	o.insert(vox);
}

}  // namespace bims::maps
