#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/pipeline/config.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/filesystem.h>

#include <stdexcept>

namespace bims::pipeline
{
const char* toString(Variant v)
{
	switch (v)
	{
		case Variant::BottomOnly:
			return "bottom-only";
		case Variant::FlowOnly:
			return "flow-only";
		case Variant::Fused:
			return "fused";
		case Variant::FusedRaycast:
			return "fused-raycast";
	}
	return "?";
}

Variant variantFromString(const std::string& s)
{
	for (Variant v : {Variant::BottomOnly, Variant::FlowOnly, Variant::Fused,
	                  Variant::FusedRaycast})
		if (s == toString(v)) return v;
	throw std::invalid_argument(
	    "unknown variant '" + s +
	    "' (one of bottom-only|flow-only|fused|fused-raycast)");
}

void PipelineParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	ConfigSection s(cfg, section);
	variant = variantFromString(
	    s.getEnum("variant", toString(variant),
	              {"bottom-only", "flow-only", "fused", "fused-raycast"}));
	warmup_frames =
	    static_cast<int>(s.getInt("warmup_frames", warmup_frames, 0, 100000));
	feedback_mask = s.getBool("feedback_mask", feedback_mask);
	imu_wait_s = s.getDouble("imu_wait_s", imu_wait_s, 0.0, 10.0);
	read_ahead = s.getBool("read_ahead", read_ahead);
	flow_thread = s.getBool("flow_thread", flow_thread);
	flow_lookahead = s.getBool("flow_lookahead", flow_lookahead);
	cloud_thread = s.getBool("cloud_thread", cloud_thread);
	opencv_threads =
	    static_cast<int>(s.getInt("opencv_threads", opencv_threads, 0, 64));
	s.finish();
}

void OutputParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section)
{
	ConfigSection s(cfg, section);
	moving_ply = s.getBool("moving_ply", moving_ply);
	static_map = s.getBool("static_map", static_map);
	labelled_rawlog = s.getBool("labelled_rawlog", labelled_rawlog);
	labelled_rawlog_gz_level = static_cast<int>(
	    s.getInt("labelled_rawlog_gz_level", labelled_rawlog_gz_level, 0, 9));
	flow_labels = s.getBool("flow_labels", flow_labels);
	static_p_occupied =
	    s.getDouble("static_p_occupied", static_p_occupied, 0.5, 0.999);
	writer_thread = s.getBool("writer_thread", writer_thread);
	s.finish();
}

void ExperimentConfig::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg)
{
	source = configSourceName(cfg);
	checkExperimentSections(cfg);
	ego.loadFromConfigFile(cfg);
	flow.loadFromConfigFile(cfg, "flow");
	grids.loadFromConfigFile(cfg, "grids");
	pipeline.loadFromConfigFile(cfg, "pipeline");
	output.loadFromConfigFile(cfg, "output");
	// import settings live in the same file (config/bonn.ini) but are
	// read by bims-import-tum only.
	if (pipeline.variant == Variant::FusedRaycast) setVariant(pipeline.variant);
}

void ExperimentConfig::loadFromFile(const std::string& path)
{
	if (!mrpt::system::fileExists(path))
		throw ConfigError(path + ": no such config file");
	bims::checkIniFile(path);
	mrpt::config::CConfigFile cfg(path);
	loadFromConfigFile(cfg);
}

void ExperimentConfig::setVariant(Variant v)
{
	pipeline.variant = v;
	if (v == Variant::FusedRaycast) grids.decay = maps::DecayMode::Raycast;
}

}  // namespace bims::pipeline
