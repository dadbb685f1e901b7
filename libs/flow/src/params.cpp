#include <bims/common/config.h>
#include <bims/flow/params.h>

namespace bims::flow
{
void FlowParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                    const std::string& section)
{
	ConfigSection s(cfg, section);
	method = s.getEnum("method", method, {"dis", "farneback"});
	dis_preset = s.getEnum("dis_preset", dis_preset,
	                       {"auto", "ultrafast", "fast", "medium"});
	downscale = static_cast<int>(s.getInt("downscale", downscale, 1, 8));
	derotate = s.getBool("derotate", derotate);
	expected = s.getEnum("expected", expected, {"exact", "linear"});
	diff_threshold_px =
	    s.getDouble("diff_threshold_px", diff_threshold_px, 0.01, 100.0);
	depth_noise_sigmas =
	    s.getDouble("depth_noise_sigmas", depth_noise_sigmas, 0.0, 20.0);
	depth_noise_a = s.getDouble("depth_noise_a", depth_noise_a, 0.0, 1.0);
	max_depth_m = s.getDouble("max_depth_m", max_depth_m, 0.1, 100.0);
	depth_edge_rel = s.getDouble("depth_edge_rel", depth_edge_rel, 0.0, 10.0);
	depth_edge_px =
	    static_cast<int>(s.getInt("depth_edge_px", depth_edge_px, 1, 50));
	visible_change_grey =
	    s.getDouble("visible_change_grey", visible_change_grey, 0.0, 255.0);
	texture_window_px = static_cast<int>(
	    s.getInt("texture_window_px", texture_window_px, 1, 63));
	refine_min_texture =
	    s.getDouble("refine_min_texture", refine_min_texture, 0.0, 1e6);
	refine_pose =
	    s.getEnum("refine_pose", refine_pose, {"none", "translation", "se3"});
	refine_to_ego = s.getBool("refine_to_ego", refine_to_ego);
	refine_step_px =
	    static_cast<int>(s.getInt("refine_step_px", refine_step_px, 1, 64));
	refine_iterations = static_cast<int>(
	    s.getInt("refine_iterations", refine_iterations, 1, 100));
	s.finish();
}

}  // namespace bims::flow
