#include <bims/common/config.h>
#include <bims/maps/grid_params.h>

#include <cmath>
#include <ostream>
#include <stdexcept>

namespace bims::maps
{
void GridParams::validate() const
{
	checkOptions(*this, "bims::maps::GridParams");
}

void GridParams::describe(OptionVisitor& v)
{
	v.real("voxel_size", voxel_size, 1e-3, 10, "edge of a cubic voxel [m]");
	v.choice("decay", decay,
	         "tier-0 cells without a reading that get the miss update: "
	         "every one (the paper), those in the view frustum, or those a "
	         "ray crosses");
	v.real("p_miss", p_miss, 1e-9, 1 - 1e-9,
	       "P(D = 0), the sensor misses an occupied cell; decay per frame "
	       "log(2 - p_miss)");
	v.real("reading_lambda", reading_lambda, 1, 1e300,
	       "tier 0/1 likelihood ratio of a reading (1: a hit only)");
	v.real("p_min", p_min, 1e-9, 0.5 - 1e-9,
	       "tier-0 clamping of the occupancy probability, lower");
	v.real("p_max", p_max, 0.5 + 1e-9, 1 - 1e-9,
	       "tier-0 clamping of the occupancy probability, upper");
	v.real("bg_transition_eps", bg_transition_eps, 1e-12, 0.5 - 1e-9,
	       "tier 1: eps = P(I=1 | O-=1)");
	v.real("p_unknown", p_unknown, 0, 1 - 1e-9,
	       "tier-0 prior of a voxel never observed (0: the paper's 0.5, "
	       "decayed)");
	v.choice("bg_neighbourhood", bg_neighbourhood,
	         "tier 1: observed neighbours whose prior can explain a hit as "
	         "background");
	v.real("flow_transition_tau", flow_transition_tau, 1e-12, 0.5 - 1e-9,
	       "tier 2: tau = P(Diff_C != I)");
	v.real("flow_lambda", flow_lambda, 1 + 1e-9, 1e300,
	       "tier-2 likelihood ratio of a reading (> 1)");
	v.choice("flow_evidence", flow_evidence,
	         "tier 2: Diff readings count for Diff_C = 1 only (symmetric) or "
	         "not at all (veto)");
	v.real("max_range", max_range, 1e-3, 1e4,
	       "readings farther than this are skipped [m]");
	v.real("extent", extent, 1e-2, 1e6,
	       "readings and rays confined to |x|,|y|,|z| <= extent in {W} [m]");
	v.rule((extent + max_range) / voxel_size < 0.9 * (1 << 20), "extent",
	       "+ max_range must be < 943718 voxels (21-bit keys)");
	v.real("max_memory_mb", max_memory_mb, 1, 1e7,
	       "memory budget of one grid's voxels [MiB]");
	v.integer("raycast_decimation", raycast_decimation, 1, 64,
	          "decay = raycast: every k-th pixel in u and v casts a ray");
	v.choice("raycast_target", raycast_target,
	         "decay = raycast: rays to each reading or to each hit voxel");
	v.real("raycast_margin", raycast_margin, 0, 1e3,
	       "decay = raycast: rays end this far before their reading, no miss "
	       "in its noise band [m]");
	v.flag("exclude_moving", exclude_moving,
	       "tier 0 integrates only the voxels called static (false: the "
	       "paper)");
	v.choice("exclude_by", exclude_by,
	         "exclude_moving: left out are the decision tier's moving voxels, "
	         "tier 1's too (either), or auto (decision with raycast, either "
	         "otherwise)");
	v.integer("raycast_threads", raycast_threads, 1, 64,
	          "decay = raycast: threads casting rays (same result)");
}

void GridParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                    const std::string& section,
                                    const std::vector<std::string>& alsoAllowed)
{
	bims::ConfigSection s(cfg, section);
	for (const auto& k : alsoAllowed) s.allow(k);
	OptionReader r(s);
	describe(r);  // ranges, choices and the rule across keys
	s.finish();
}

void GridParams::dump(std::ostream& o) const
{
	for (const auto& r : optionRows(*this))
		o << r.key << "=" << r.value << "\n";
}

bool GridParams::operator==(const GridParams& o) const
{
	const auto a = optionRows(*this), b = optionRows(o);
	for (size_t i = 0; i < a.size(); i++)
		if (a[i].value != b[i].value) return false;
	return true;
}

}  // namespace bims::maps
