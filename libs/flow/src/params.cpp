#include <bims/common/config.h>
#include <bims/flow/params.h>

namespace bims::flow
{
void FlowParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                    const std::string& section)
{
	ConfigSection s(cfg, section);
	method = s.getEnum("method", method, {"dis", "farneback"});
	dis_preset =
	    s.getEnum("dis_preset", dis_preset, {"ultrafast", "fast", "medium"});
	downscale = static_cast<int>(s.getInt("downscale", downscale, 1, 8));
	expected = s.getEnum("expected", expected, {"exact", "linear"});
	diff_threshold_px =
	    s.getDouble("diff_threshold_px", diff_threshold_px, 0.01, 100.0);
	depth_noise_sigmas =
	    s.getDouble("depth_noise_sigmas", depth_noise_sigmas, 0.0, 20.0);
	depth_noise_a = s.getDouble("depth_noise_a", depth_noise_a, 0.0, 1.0);
	max_depth_m = s.getDouble("max_depth_m", max_depth_m, 0.1, 100.0);
	s.finish();
}

}  // namespace bims::flow
