// Parameters of the flow module, section [flow] of an experiment .ini.
// Defaults: config/default.ini's model (docs/config.md lists every key).
#pragma once

#include <bims/common/choice.h>
#include <bims/common/options.h>
#include <mrpt/config/CConfigFileBase.h>

#include <string>

namespace bims::flow
{
/** Dense observed flow algorithm. */
enum class FlowMethod
{
	Dis,       ///< OpenCV DIS
	Farneback  ///< OpenCV Farneback
};
inline Choices<FlowMethod> choices(FlowMethod)
{
	static constexpr ChoiceName<FlowMethod> t[] = {
	    {FlowMethod::Dis, "dis"}, {FlowMethod::Farneback, "farneback"}};
	return t;
}

/** DIS preset; Auto is ultrafast on images >= 640 px wide, fast below
 * (disPresetFor()). */
enum class DisPreset
{
	Auto,
	Ultrafast,
	Fast,
	Medium
};
inline Choices<DisPreset> choices(DisPreset)
{
	static constexpr ChoiceName<DisPreset> t[] = {
	    {DisPreset::Auto, "auto"},
	    {DisPreset::Ultrafast, "ultrafast"},
	    {DisPreset::Fast, "fast"},
	    {DisPreset::Medium, "medium"}};
	return t;
}

/** Expected flow model. */
enum class ExpectedFlowModel
{
	Exact,  ///< exact reprojection
	Linear  ///< first-order Jacobian (the paper's eq. 8)
};
inline Choices<ExpectedFlowModel> choices(ExpectedFlowModel)
{
	static constexpr ChoiceName<ExpectedFlowModel> t[] = {
	    {ExpectedFlowModel::Exact, "exact"},
	    {ExpectedFlowModel::Linear, "linear"}};
	return t;
}

/** The relative pose of the expected flow (flow_pose.h). */
enum class RefinePose
{
	None,         ///< the egomotion's T_CprevC as it is
	Translation,  ///< its rotation kept, translation fitted to the flow
	SE3           ///< rotation and translation fitted to the flow
};
inline Choices<RefinePose> choices(RefinePose)
{
	static constexpr ChoiceName<RefinePose> t[] = {
	    {RefinePose::None, "none"},
	    {RefinePose::Translation, "translation"},
	    {RefinePose::SE3, "se3"}};
	return t;
}

/** Options of observed flow, expected flow and Diff/notDiff labelling. */
struct FlowParams
{
	FlowMethod method = FlowMethod::Dis;     ///< dense observed flow
	DisPreset dis_preset = DisPreset::Auto;  ///< method = dis
	/** Observed flow is computed on images downscaled by this integer
	 * factor (1 = full resolution) and upsampled (vectors scaled back). */
	int downscale = 1;
	/** Measure the observed flow after warping frame t-1 by the rotation
	 * of the egomotion (ObservedFlow::computeDerotated): DIS then only
	 * searches the residual motion, which keeps it right under fast camera
	 * rotation. */
	bool derotate = true;
	ExpectedFlowModel expected = ExpectedFlowModel::Exact;
	/** A pixel is Diff when |observed - expected| exceeds this [px]... */
	double diff_threshold_px = 1.0;
	/** ...plus this many standard deviations of the expected flow caused by
	 * depth noise (0 = disabled). */
	double depth_noise_sigmas = 0.0;
	/** Depth noise model sigma_z = depth_noise_a * z^2 [1/m]. */
	double depth_noise_a = 0.0030;
	/** Readings farther than this get no label [m]. */
	double max_depth_m = 6.0;
	/** Pixels on a depth discontinuity (a neighbour depth_edge_px away
	 * differs by more than depth_edge_rel of the nearer depth, or has no
	 * reading) get no label: the current depth and the observed flow
	 * disagree there (0 = off). */
	double depth_edge_rel = 0.0;
	int depth_edge_px = 2;
	/** A pixel is Diff only if the flow difference d would change the image
	 * by at least this many grey levels RMS over the texture window,
	 * sqrt(d^T S d) with S the structure tensor (observed_flow.h): on
	 * textureless walls and along edges (aperture) the observed flow cannot
	 * tell d, and real DIS flow is wrong there (0 = off). */
	double visible_change_grey = 4.0;
	int texture_window_px = 9;  ///< side of the structure-tensor window [px]
	/** Relative pose for the expected flow (RefinePose; flow_pose.h). */
	RefinePose refine_pose = RefinePose::None;
	/** Hand the refined motion back to the egomotion (T_WC, the grids'
	 * pose, follows it) or use it for the expected flow only. */
	bool refine_to_ego = true;
	int refine_step_px = 4;      ///< grid step of the samples [px]
	int refine_iterations = 12;  ///< robust Gauss-Newton iterations
	/** Samples of the refinement need a structure-tensor minimum eigenvalue
	 * of at least this [(grey level / px)^2]: flow on textureless surfaces
	 * is not measured. */
	double refine_min_texture = 4.0;

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);
	/** Reads section \a section (default [flow]); unknown keys and
	 * out-of-range values throw bims::ConfigError. */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "flow");
};

}  // namespace bims::flow
