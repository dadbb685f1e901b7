// Parameters of the flow module, section [flow] of an experiment .ini.
#pragma once

#include <mrpt/config/CConfigFileBase.h>

#include <string>

namespace bims::flow
{
/** Options of observed flow, expected flow and Diff/notDiff labelling. */
struct FlowParams
{
	/** Dense observed flow: "dis" (OpenCV DIS) or "farneback". */
	std::string method = "dis";
	/** DIS preset: "ultrafast", "fast", "medium", or "auto" (ultrafast on
	 * images >= 640 px wide, fast below: disPresetFor()). */
	std::string dis_preset = "fast";
	/** Observed flow is computed on images downscaled by this integer
	 * factor (1 = full resolution) and upsampled (vectors scaled back). */
	int downscale = 1;
	/** Measure the observed flow after warping frame t-1 by the rotation
	 * of the egomotion (ObservedFlow::computeDerotated): DIS then only
	 * searches the residual motion, which keeps it right under fast camera
	 * rotation. */
	bool derotate = false;
	/** Expected flow: "exact" reprojection, or "linear" (first-order
	 * Jacobian, the paper's eq. 8). */
	std::string expected = "exact";
	/** A pixel is Diff when |observed - expected| exceeds this [px]... */
	double diff_threshold_px = 1.5;
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
	double visible_change_grey = 0.0;
	int texture_window_px = 9;  ///< side of the structure-tensor window [px]
	/** Relative pose for the expected flow: "none" (the egomotion's
	 * T_CprevC as it is), "translation" (its rotation kept, e.g. the IMU's;
	 * translation fitted to the dense observed flow) or "se3" (rotation and
	 * translation fitted to the observed flow, vision only); flow_pose.h. */
	std::string refine_pose = "none";
	/** Hand the refined motion back to the egomotion (T_WC, the grids'
	 * pose, follows it) or use it for the expected flow only. */
	bool refine_to_ego = true;
	int refine_step_px = 4;      ///< grid step of the samples [px]
	int refine_iterations = 12;  ///< robust Gauss-Newton iterations
	/** Samples of the refinement need a structure-tensor minimum eigenvalue
	 * of at least this [(grey level / px)^2]: flow on textureless surfaces
	 * is not measured. */
	double refine_min_texture = 4.0;

	/** Reads section \a section (default [flow]); unknown keys and
	 * out-of-range values throw bims::ConfigError. */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "flow");
};

}  // namespace bims::flow
