#include <bims/common/config.h>
#include <bims/common/experiment.h>

namespace bims
{
const std::vector<std::string>& experimentSections()
{
	static const std::vector<std::string> s = {
	    "camera",        // intrinsics, size, depth scale of the RGB-D sensor
	    "sensors",       // sensor labels in the rawlog
	    "calibration",   // R_IC, IMU-camera time offset
	    "import",        // TUM/Bonn import (association, ground truth)
	    "import_stray",  // Stray Scanner import (confidence, colour size)
	    "import_bag",    // ROS 1 bag import (topics, pairing)
	    "attitude",      // ego: IMU attitude filter
	    "tracker",       // ego: gyro-aided KLT
	    "translation",   // ego: robust translation / refinement
	    "odometry",      // ego: overall egomotion mode
	    "anchor",        // ego: map-anchored (keyframe) tracking
	    "depth_correction",  // ego: depth sensor's smooth distortion
	    "grids",             // maps: the three Bayesian grids
	    "flow",              // flow: observed / expected flow, Diff labels
	    "pipeline",          // pipeline: orchestration, variants
	    "output",            // what bims-run writes
	    "input",             // size limits of input image files
	};
	return s;
}

void checkExperimentSections(const mrpt::config::CConfigFileBase& cfg)
{
	checkSections(cfg, experimentSections(), {"map"});
}

}  // namespace bims
