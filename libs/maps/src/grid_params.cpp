#include <bims/common/config.h>
#include <bims/maps/grid_params.h>

#include <cmath>
#include <ostream>
#include <stdexcept>

namespace bims::maps
{
const char* toString(DecayMode m)
{
	switch (m)
	{
		case DecayMode::All:
			return "all";
		case DecayMode::Frustum:
			return "frustum";
		case DecayMode::Raycast:
			return "raycast";
	}
	return "?";
}
const char* toString(FlowEvidence e)
{
	return e == FlowEvidence::Veto ? "veto" : "symmetric";
}
const char* toString(RayTarget t)
{
	return t == RayTarget::Voxels ? "voxels" : "points";
}
const char* toString(ExcludeBy e)
{
	switch (e)
	{
		case ExcludeBy::Decision:
			return "decision";
		case ExcludeBy::Either:
			return "either";
		case ExcludeBy::Auto:
			return "auto";
	}
	return "?";
}

const char* toString(BgNeighbourhood n)
{
	switch (n)
	{
		case BgNeighbourhood::None:
			return "none";
		case BgNeighbourhood::Ray:
			return "ray";
		case BgNeighbourhood::Faces:
			return "faces";
		case BgNeighbourhood::Block:
			return "block";
	}
	return "?";
}

namespace
{
void check(bool ok, const char* name, const std::string& what)
{
	if (!ok)
		throw std::invalid_argument(std::string("bims::maps::GridParams: ") +
		                            name + " " + what);
}
}  // namespace

void GridParams::validate() const
{
	check(std::isfinite(voxel_size) && voxel_size >= 1e-3 && voxel_size <= 10,
	      "voxel_size", "must be in [0.001, 10] m");
	check(p_miss > 0 && p_miss < 1, "p_miss", "must be in (0, 1)");
	check(std::isfinite(reading_lambda) && reading_lambda >= 1,
	      "reading_lambda", "must be finite and >= 1");
	check(p_min > 0 && p_min < 0.5 && p_max > 0.5 && p_max < 1, "p_min/p_max",
	      "must satisfy 0 < p_min < 0.5 < p_max < 1");
	check(bg_transition_eps > 0 && bg_transition_eps < 0.5, "bg_transition_eps",
	      "must be in (0, 0.5)");
	check(p_unknown >= 0 && p_unknown < 1, "p_unknown",
	      "must be in [0, 1) (0 = the paper's prior)");
	check(flow_transition_tau > 0 && flow_transition_tau < 0.5,
	      "flow_transition_tau", "must be in (0, 0.5)");
	check(std::isfinite(flow_lambda) && flow_lambda > 1, "flow_lambda",
	      "must be finite and > 1 (with 1, tier 2 carries no evidence)");
	check(max_range > 0 && std::isfinite(max_range), "max_range",
	      "must be > 0");
	check(extent > 0 && std::isfinite(extent), "extent", "must be > 0");
	check((extent + max_range) / voxel_size < 0.9 * (1 << 20), "extent",
	      "+ max_range must be < 943718 voxels (21-bit keys)");
	check(max_memory_mb >= 1, "max_memory_mb", "must be >= 1");
	check(raycast_decimation >= 1 && raycast_decimation <= 64,
	      "raycast_decimation", "must be in [1, 64]");
	check(raycast_threads >= 1 && raycast_threads <= 64, "raycast_threads",
	      "must be in [1, 64]");
}

void GridParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                    const std::string& section,
                                    const std::vector<std::string>& alsoAllowed)
{
	bims::ConfigSection s(cfg, section);
	for (const auto& k : alsoAllowed) s.allow(k);
	voxel_size = s.getDouble("voxel_size", voxel_size, 1e-3, 10);
	const auto d =
	    s.getEnum("decay", toString(decay), {"all", "frustum", "raycast"});
	decay = d == "all"
	            ? DecayMode::All
	            : (d == "frustum" ? DecayMode::Frustum : DecayMode::Raycast);
	p_miss = s.getDouble("p_miss", p_miss, 1e-9, 1 - 1e-9);
	reading_lambda = s.getDouble("reading_lambda", reading_lambda, 1, 1e300);
	p_min = s.getDouble("p_min", p_min, 1e-9, 0.5 - 1e-9);
	p_max = s.getDouble("p_max", p_max, 0.5 + 1e-9, 1 - 1e-9);
	bg_transition_eps =
	    s.getDouble("bg_transition_eps", bg_transition_eps, 1e-12, 0.5 - 1e-9);
	p_unknown = s.getDouble("p_unknown", p_unknown, 0, 1 - 1e-9);
	const auto nb = s.getEnum("bg_neighbourhood", toString(bg_neighbourhood),
	                          {"none", "ray", "faces", "block"});
	bg_neighbourhood = nb == "ray"     ? BgNeighbourhood::Ray
	                   : nb == "faces" ? BgNeighbourhood::Faces
	                   : nb == "block" ? BgNeighbourhood::Block
	                                   : BgNeighbourhood::None;
	flow_transition_tau = s.getDouble("flow_transition_tau",
	                                  flow_transition_tau, 1e-12, 0.5 - 1e-9);
	flow_lambda = s.getDouble("flow_lambda", flow_lambda, 1 + 1e-9, 1e300);
	const auto e = s.getEnum("flow_evidence", toString(flow_evidence),
	                         {"symmetric", "veto"});
	flow_evidence = e == "veto" ? FlowEvidence::Veto : FlowEvidence::Symmetric;
	max_range = s.getDouble("max_range", max_range, 1e-3, 1e4);
	extent = s.getDouble("extent", extent, 1e-2, 1e6);
	max_memory_mb = s.getDouble("max_memory_mb", max_memory_mb, 1, 1e7);
	raycast_decimation =
	    int(s.getInt("raycast_decimation", raycast_decimation, 1, 64));
	const auto t = s.getEnum("raycast_target", toString(raycast_target),
	                         {"points", "voxels"});
	raycast_target = t == "voxels" ? RayTarget::Voxels : RayTarget::Points;
	exclude_moving = s.getBool("exclude_moving", exclude_moving);
	const auto xb = s.getEnum("exclude_by", toString(exclude_by),
	                          {"decision", "either", "auto"});
	exclude_by = xb == "either" ? ExcludeBy::Either
	             : xb == "auto" ? ExcludeBy::Auto
	                            : ExcludeBy::Decision;
	raycast_threads = int(s.getInt("raycast_threads", raycast_threads, 1, 64));
	s.finish();
	try
	{
		validate();
	}
	catch (const std::invalid_argument& ex)
	{
		s.fail("", ex.what());
	}
}

void GridParams::dump(std::ostream& o) const
{
	o << "voxel_size=" << voxel_size << "\ndecay=" << toString(decay)
	  << "\np_miss=" << p_miss << "\nreading_lambda=" << reading_lambda
	  << "\np_min=" << p_min << "\np_max=" << p_max
	  << "\nbg_transition_eps=" << bg_transition_eps
	  << "\np_unknown=" << p_unknown
	  << "\nbg_neighbourhood=" << toString(bg_neighbourhood)
	  << "\nflow_transition_tau=" << flow_transition_tau
	  << "\nflow_lambda=" << flow_lambda
	  << "\nflow_evidence=" << toString(flow_evidence)
	  << "\nmax_range=" << max_range << "\nextent=" << extent
	  << "\nmax_memory_mb=" << max_memory_mb
	  << "\nraycast_decimation=" << raycast_decimation
	  << "\nraycast_target=" << toString(raycast_target)
	  << "\nexclude_moving=" << (exclude_moving ? "true" : "false")
	  << "\nexclude_by=" << toString(exclude_by)
	  << "\nraycast_threads=" << raycast_threads << "\n";
}

bool GridParams::operator==(const GridParams& o) const
{
	return voxel_size == o.voxel_size && decay == o.decay &&
	       p_miss == o.p_miss && reading_lambda == o.reading_lambda &&
	       p_min == o.p_min && p_max == o.p_max &&
	       bg_transition_eps == o.bg_transition_eps &&
	       p_unknown == o.p_unknown && bg_neighbourhood == o.bg_neighbourhood &&
	       flow_transition_tau == o.flow_transition_tau &&
	       flow_lambda == o.flow_lambda && flow_evidence == o.flow_evidence &&
	       max_range == o.max_range && extent == o.extent &&
	       max_memory_mb == o.max_memory_mb &&
	       raycast_decimation == o.raycast_decimation &&
	       raycast_target == o.raycast_target &&
	       exclude_moving == o.exclude_moving && exclude_by == o.exclude_by &&
	       raycast_threads == o.raycast_threads;
}

}  // namespace bims::maps
