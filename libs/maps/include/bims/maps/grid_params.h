// Parameters of the three Bayesian voxel grids (experiment .ini section
// [grids], or the creationOpts section of an MRPT map definition).
// The model and the reasons for every default: docs/model.md. The defaults
// are config/default.ini's model; config/paper.ini is the paper's literal one.
#pragma once

#include <bims/common/choice.h>
#include <bims/common/options.h>
#include <mrpt/config/CConfigFileBase.h>

#include <cstddef>
#include <iosfwd>
#include <string>

namespace bims::maps
{
/** Which tier-0 cells that got no reading in a frame receive the "miss"
 * update -log(2 - P_miss) (docs/model.md, "Decay"). */
enum class DecayMode
{
	/** Every cell of the (unbounded) grid, also outside the view: the
	 * paper's literal model. Applied lazily, O(points) per frame. */
	All,
	/** Existing cells inside the view frustum and in front of the measured
	 * depth at their pixel. */
	Frustum,
	/** Cells traversed by a sensor ray (3D DDA) before its hit. */
	Raycast
};
inline Choices<DecayMode> choices(DecayMode)
{
	static constexpr ChoiceName<DecayMode> t[] = {
	    {DecayMode::All, "all"},
	    {DecayMode::Frustum, "frustum"},
	    {DecayMode::Raycast, "raycast"}};
	return t;
}

/** How tier 2 reads a Diff-labelled reading (docs/model.md, tier 2). */
enum class FlowEvidence
{
	/** Diff readings are Dirac only for Diff_C = 1 (default). */
	Symmetric,
	/** Literal reading: Diff readings are Dirac for either value, so only
	 * consistent flow carries evidence (tier 2 can only filter tier 1). */
	Veto
};
inline Choices<FlowEvidence> choices(FlowEvidence)
{
	static constexpr ChoiceName<FlowEvidence> t[] = {
	    {FlowEvidence::Symmetric, "symmetric"}, {FlowEvidence::Veto, "veto"}};
	return t;
}

/** Which observed tier-0 voxels next to a hit voxel can explain its
 * readings as background (tier 1's O- is their largest prior). */
enum class BgNeighbourhood
{
	/** The voxel alone (the paper). */
	None,
	/** The voxels one edge in front of and behind the voxel centre along
	 * the sensor ray, where depth noise and grazing rays put readings. */
	Ray,
	/** The 6 face neighbours. */
	Faces,
	/** The 26 neighbours of the 3x3x3 block. */
	Block
};
inline Choices<BgNeighbourhood> choices(BgNeighbourhood)
{
	static constexpr ChoiceName<BgNeighbourhood> t[] = {
	    {BgNeighbourhood::None, "none"},
	    {BgNeighbourhood::Ray, "ray"},
	    {BgNeighbourhood::Faces, "faces"},
	    {BgNeighbourhood::Block, "block"}};
	return t;
}

/** Which end point a free-space ray goes to (decay = raycast). */
enum class RayTarget
{
	/** One ray per reading, to the reading itself (exact). */
	Points,
	/** One ray per distinct hit voxel, to its centre (OctoMap's
	 * "discretize" option): fewer rays, same hit cells. */
	Voxels
};
inline Choices<RayTarget> choices(RayTarget)
{
	static constexpr ChoiceName<RayTarget> t[] = {
	    {RayTarget::Points, "points"}, {RayTarget::Voxels, "voxels"}};
	return t;
}

/** MotionGrids with exclude_moving: which voxels tier 0 leaves out. */
enum class ExcludeBy
{
	Decision,  ///< those the decision tier (2, or 1 for bottom-only) calls
	           ///< moving
	Either,    ///< those tier 1 or the decision tier calls moving
	Auto       ///< Either, but Decision with decay = raycast (docs/model.md)
};
inline Choices<ExcludeBy> choices(ExcludeBy)
{
	static constexpr ChoiceName<ExcludeBy> t[] = {
	    {ExcludeBy::Decision, "decision"},
	    {ExcludeBy::Either, "either"},
	    {ExcludeBy::Auto, "auto"}};
	return t;
}

/** All parameters of the grids. Probabilities are in (0, 1); log-odds are
 * natural logarithms. Defaults are explained in docs/model.md. */
struct GridParams
{
	/** Edge of a cubic voxel [m]. */
	double voxel_size = 0.05;
	/** Which unobserved cells decay (tier 0). */
	DecayMode decay = DecayMode::Raycast;
	/** P(D = 0): probability that the sensor misses an occupied cell. Also
	 * sets the decay per frame, log(2 - p_miss). */
	double p_miss = 0.1;
	/** Tier 0/1 per-reading likelihood ratio lambda (>= 1); 1 means that a
	 * reading carries no evidence beyond "the cell was hit". */
	double reading_lambda = 1.0;
	/** Tier-0 clamping of the occupancy probability: [p_min, p_max]. */
	double p_min = 0.12;
	double p_max = 0.999;
	/** Tier 1: eps = P(I=1 | O-=1) = 1 - P(I=1 | O-=0). */
	double bg_transition_eps = 0.001;
	/** Tier 0: occupancy prior of a voxel never observed (its value when
	 * its first hit or miss arrives, O- for tier 1 and the query value of
	 * unseen space). 0 = the paper: 0.5, decayed by every frame so far
	 * under decay = all. A value near 1 reads unseen space as static scene,
	 * so that tier 1 does not flag every newly seen surface and the flow
	 * decides there (docs/model.md). */
	double p_unknown = 0.97;
	/** Tier 1: O- of a hit voxel is the largest tier-0 prior over the voxel
	 * and these observed neighbours (docs/model.md). */
	BgNeighbourhood bg_neighbourhood = BgNeighbourhood::Ray;
	/** Tier 2: tau = P(Diff_C != I). */
	double flow_transition_tau = 0.03;
	/** Tier 2 per-reading likelihood ratio (must be > 1). */
	double flow_lambda = 4.0;
	/** Tier 2 reading of Diff labels. */
	FlowEvidence flow_evidence = FlowEvidence::Symmetric;
	/** Readings farther than this from the sensor are skipped [m]. */
	double max_range = 8.0;
	/** Readings and rays are confined to the cube |x|,|y|,|z| <= extent in
	 * {W} [m]; points outside are skipped and counted. */
	double extent = 500.0;
	/** Memory budget of one grid's voxel storage [MiB]; cells that would
	 * exceed it are not created (counted, warned once). */
	double max_memory_mb = 4096;
	/** decay = raycast: every k-th pixel in u and in v casts a free-space
	 * ray (hits always use every pixel). 1 = full resolution. */
	int raycast_decimation = 1;
	/** decay = raycast: rays to each reading or to each hit voxel. */
	RayTarget raycast_target = RayTarget::Voxels;
	/** decay = raycast: a ray ends this far before its reading [m], so the
	 * voxels in the reading's noise band get no miss (the free region of
	 * the inverse sensor model, r < z - alpha/2; docs/model.md). 0: up to
	 * the hit voxel. */
	double raycast_margin = 0.1;
	/** MotionGrids: tier 0 (the background of tier 1) integrates only the
	 * voxels that the motion decision of this frame calls static; a voxel
	 * labelled moving keeps its belief (no hit, no miss). false = the
	 * paper: every reading is folded into tier 0. */
	bool exclude_moving = true;
	/** exclude_moving: the voxels left out (see ExcludeBy). */
	ExcludeBy exclude_by = ExcludeBy::Auto;
	/** decay = raycast: threads casting the free-space rays of a frame
	 * (the result does not depend on it). A setting of the process, not of
	 * the map: not serialised (a loaded map has 1). */
	int raycast_threads = 1;

	/** Throws std::invalid_argument naming the parameter if inconsistent. */
	void validate() const;

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);

	/** Reads the keys above from \a section (strict: unknown keys throw
	 * bims::ConfigError naming file, section and key). Keys in
	 * \a alsoAllowed are accepted without being read. */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section,
	                        const std::vector<std::string>& alsoAllowed = {});

	/** Writes every key as key=value lines (for dumps). */
	void dump(std::ostream& out) const;

	/** Every key has the same value. */
	bool operator==(const GridParams& o) const;
	bool operator!=(const GridParams& o) const { return !(*this == o); }
};

}  // namespace bims::maps
