#include <bims/common/config.h>
#include <bims/flow/params.h>

namespace bims::flow
{
void FlowParams::describe(OptionVisitor& v)
{
	v.choice("method", method, "dense observed flow");
	v.choice("dis_preset", dis_preset,
	         "DIS preset (auto: ultrafast on images >= 640 px wide, fast "
	         "below)");
	v.integer("downscale", downscale, 1, 8,
	          "observed flow on images downscaled by this factor");
	v.flag("derotate", derotate,
	       "measure the flow after warping frame t-1 by the egomotion's "
	       "rotation");
	v.choice("expected", expected,
	         "expected flow: exact reprojection or linear (the paper's eq. 8)");
	v.real("diff_threshold_px", diff_threshold_px, 0.01, 100.0,
	       "Diff when |observed - expected flow| exceeds this [px]");
	v.real("depth_noise_sigmas", depth_noise_sigmas, 0.0, 20.0,
	       "... plus this many std. dev. of the expected flow from depth "
	       "noise (0 = off)");
	v.real("depth_noise_a", depth_noise_a, 0.0, 1.0,
	       "depth noise sigma_z = a z^2 [1/m]");
	v.real("max_depth_m", max_depth_m, 0.1, 100.0,
	       "readings farther than this get no label [m]");
	v.real("depth_edge_rel", depth_edge_rel, 0.0, 10.0,
	       "no label on depth discontinuities beyond this relative step (0 "
	       "= off)");
	v.integer("depth_edge_px", depth_edge_px, 1, 50,
	          "distance of the neighbour of the depth-edge test [px]");
	v.real("visible_change_grey", visible_change_grey, 0.0, 255.0,
	       "Diff only where the flow difference changes the image by this "
	       "many grey levels RMS (0 = off)");
	v.integer("texture_window_px", texture_window_px, 1, 63,
	          "side of the structure-tensor window [px]");
	v.choice("refine_pose", refine_pose,
	         "relative pose of the expected flow fitted to the observed flow "
	         "(none, translation only, or se3)");
	v.flag("refine_to_ego", refine_to_ego,
	       "hand the refined motion back to the egomotion");
	v.integer("refine_step_px", refine_step_px, 1, 64,
	          "grid step of the refinement's samples [px]");
	v.integer("refine_iterations", refine_iterations, 1, 100,
	          "robust Gauss-Newton iterations of the refinement");
	v.real("refine_min_texture", refine_min_texture, 0.0, 1e6,
	       "least structure-tensor eigenvalue of a refinement sample "
	       "[(grey level / px)^2]");
}

void FlowParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                    const std::string& section)
{
	readOptions(*this, cfg, section);
}

}  // namespace bims::flow
