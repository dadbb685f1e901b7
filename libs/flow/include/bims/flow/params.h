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
	/** DIS preset: "ultrafast", "fast" or "medium". */
	std::string dis_preset = "fast";
	/** Observed flow is computed on images downscaled by this integer
	 * factor (1 = full resolution) and upsampled (vectors scaled back). */
	int downscale = 1;
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

	/** Reads section \a section (default [flow]); unknown keys and
	 * out-of-range values throw bims::ConfigError. */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "flow");
};

}  // namespace bims::flow
