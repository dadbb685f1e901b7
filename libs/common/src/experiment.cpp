#include <bims/common/config.h>
#include <bims/common/experiment.h>

#include <stdexcept>

namespace bims
{
const std::vector<ExperimentSection>& experimentSectionTable()
{
	static const std::vector<ExperimentSection> t = {
	    {"sensors", "sensors (every program)", "sensor labels in the rawlog"},
	    {"calibration", "sensors (every program)", "IMU-camera extrinsics"},
	    {"camera", "sensors (every program)", "intrinsics"},
	    {"depth_correction", "sensors; fitted by bims-calib-depth",
	     "the depth sensor's smooth distortion"},
	    {"attitude", "ego", "IMU attitude filter"},
	    {"tracker", "ego", "gyro-aided KLT"},
	    {"translation", "ego", "robust translation and refinement"},
	    {"odometry", "ego", "the egomotion's mode"},
	    {"anchor", "ego", "map-anchored (keyframe) tracking"},
	    {"inertial", "ego", "depth-inertial translation filter"},
	    {"flow", "flow", "observed and expected flow, Diff labels"},
	    {"grids", "maps", "the three Bayesian grids"},
	    {"pipeline", "pipeline", "orchestration, variant"},
	    {"output", "pipeline (bims-run)", "what bims-run writes"},
	    {"input", "io (bims-run, the three importers, bims-flow-labels)",
	     "size limits of input image files"},
	    {"import", "eval (bims-import-tum)",
	     "TUM/Bonn import: association, ground truth"},
	    {"import_stray", "eval (bims-import-stray)",
	     "Stray Scanner import: confidence, colour size"},
	    {"import_bag", "bag (bims-import-bag)",
	     "ROS 1 bag import: topics, pairing"},
	    {"ros2", "ros2 (bims-ros2)", "ROS 2 live node: topics, QoS, frames"},
	};
	return t;
}

const std::vector<std::string>& experimentSections()
{
	static const std::vector<std::string> names = []
	{
		std::vector<std::string> n;
		for (const auto& s : experimentSectionTable()) n.push_back(s.name);
		return n;
	}();
	return names;
}

const ExperimentSection& experimentSection(const std::string& name)
{
	for (const auto& s : experimentSectionTable())
		if (name == s.name) return s;
	throw std::logic_error("[" + name +
	                       "]: not a section of the experiment "
	                       ".ini (bims/common/experiment.h)");
}

void checkExperimentSections(const mrpt::config::CConfigFileBase& cfg)
{
	checkSections(cfg, experimentSections(), {"map"});
}

}  // namespace bims
