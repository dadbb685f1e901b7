#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/common/share.h>
#include <bims/common/so3.h>
#include <bims/ego/params.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/filesystem.h>

#include <Eigen/SVD>

#include <cmath>
#include <sstream>

namespace bims::ego
{

void AttitudeParams::describe(OptionVisitor& v)
{
	v.real("kp", kp, 0, 100, "proportional correction gain [1/s]");
	v.real("ki", ki, 0, 100, "gyro-bias integral gain [1/s^2]");
	v.real("kp_init", kp_init, 0, 1000,
	       "gain during the first init_time_s [1/s]");
	v.real("init_time_s", init_time_s, 0, 3600,
	       "fast-convergence phase length [s]");
	v.flag("use_magnetometer", use_magnetometer,
	       "false: heading from the gyro only");
	v.flag("use_sensor_orientation", use_sensor_orientation,
	       "take R_WI from the sensor's own orientation quaternion when "
	       "present instead of filtering");
	v.real("gravity", gravity, 9.7, 9.9, "local gravity magnitude [m/s^2]");
	v.real("accel_gate", accel_gate, 0, 100,
	       "accelerometer used only if | |f| - gravity | is below this "
	       "[m/s^2]");
	v.real("accel_angle_gate_deg", accel_angle_gate_deg, 0, 180,
	       "... and if measured and predicted gravity differ by less than "
	       "this [deg]");
	v.real("accel_gate_max_s", accel_gate_max_s, 0, 3600,
	       "... unless they have disagreed for longer than this [s]");
	v.real("mag_norm_gate", mag_norm_gate, 0, 10,
	       "magnetometer used only if | |m| / m_ref - 1 | is below this");
	v.real("mag_dip_gate_deg", mag_dip_gate_deg, 0, 180,
	       "... and if |dip - dip_ref| is below this [deg]");
	v.real("mag_heading_gate_deg", mag_heading_gate_deg, 0, 180,
	       "... and if its heading innovation is below this [deg]");
	v.real("mag_gate_max_s", mag_gate_max_s, 0, 1e6,
	       "... unless that has lasted this long [s]");
	v.real("kp_mag", kp_mag, 0, 100, "heading correction gain [1/s]");
	v.choice("mag_reference", mag_reference,
	         "auto: norm and dip learnt from the first samples; fixed: "
	         "mag_norm and mag_dip_deg");
	v.integer("mag_reference_samples", mag_reference_samples, 1, 100000,
	          "samples that learn the reference field (auto)");
	v.real("mag_norm", mag_norm, 1e-9, 1e9,
	       "reference |m| in sensor units (fixed)");
	v.real("mag_dip_deg", mag_dip_deg, -90, 90,
	       "reference dip below horizontal [deg] (fixed)");
	v.real("max_gap_s", max_gap_s, 1e-4, 100,
	       "a gap between IMU samples longer than this is flagged [s]");
	v.real("history_s", history_s, 0.1, 3600,
	       "attitude history kept for queries [s]");
}

void AttitudeParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	readOptions(*this, cfg, section);
}

void TrackerParams::describe(OptionVisitor& v)
{
	v.integer("max_features", max_features, 8, 100000,
	          "features kept per frame");
	v.integer("grid_cols", grid_cols, 1, 100, "replenishment grid columns");
	v.integer("grid_rows", grid_rows, 1, 100, "replenishment grid rows");
	v.real("min_distance_px", min_distance_px, 1, 1000,
	       "least spacing of new features [px]");
	v.choice("detector", detector, "corner detector of new features");
	v.integer("fast_threshold", fast_threshold, 1, 255,
	          "FAST intensity threshold [grey levels]");
	v.real("gftt_quality", gftt_quality, 1e-6, 1,
	       "goodFeaturesToTrack quality level");
	v.integer("window", window, 5, 101, "LK window side [px] (odd)");
	v.rule(window % 2 == 1, "window", "must be odd");
	v.integer("pyramid_levels", pyramid_levels, 0, 8,
	          "LK max pyramid level (0 = none)");
	v.integer("max_iterations", max_iterations, 1, 1000,
	          "LK iterations per level");
	v.real("epsilon", epsilon, 1e-6, 10, "LK convergence [px]");
	v.real("fb_threshold_px", fb_threshold_px, 0.01, 100,
	       "forward-backward error limit [px]");
	v.real("border_px", border_px, 0, 200,
	       "tracks closer to the border are dropped [px]");
	v.integer("mask_dilate_px", mask_dilate_px, 0, 200,
	          "growth of the moving-region mask [px]");
}

void TrackerParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                       const std::string& section)
{
	readOptions(*this, cfg, section);
}

void TranslationParams::describe(OptionVisitor& v)
{
	v.choice("method", method, "robust estimator");
	v.integer("iterations", iterations, 1, 1000000,
	          "hypotheses of the 1-point translation model");
	v.integer("vision_iterations", vision_iterations, 1, 1000000,
	          "hypotheses of the 3-point SE(3) model");
	v.real("inlier_threshold_m", inlier_threshold_m, 1e-5, 10,
	       "inlier threshold on the 3D residual, a of a + b z^2 [m]");
	v.real("inlier_threshold_z2", inlier_threshold_z2, 0, 10,
	       "b of a + b z^2 [1/m]");
	v.integer("min_inliers", min_inliers, 3, 100000,
	          "fewer inliers: the frame is flagged failed");
	v.real("min_depth_m", min_depth_m, 0, 100,
	       "depth readings below this are unused [m]");
	v.real("max_depth_m", max_depth_m, 0.01, 1000,
	       "depth readings above this are unused [m]");
	v.rule(max_depth_m > min_depth_m, "max_depth_m",
	       "must be greater than min_depth_m");
	v.choice("refine", refine,
	         "none: IMU rotation kept; se3: Gauss-Newton over R and t with "
	         "the IMU rotation as a prior");
	v.real("rotation_prior_sigma_deg", rotation_prior_sigma_deg, 1e-4, 180,
	       "IMU rotation std. dev. (refine = se3) [deg]");
	v.real("point_sigma_m", point_sigma_m, 1e-6, 10,
	       "3D residual std. dev. at 1 m [m]");
	v.flag("reprojection", reprojection,
	       "final reprojection refinement of the robust 3D estimate");
	v.real("reprojection_sigma_px", reprojection_sigma_px, 1e-3, 100,
	       "pixel noise (Huber scale) [px]");
	v.real("reprojection_threshold_px", reprojection_threshold_px, 0.1, 1000,
	       "reprojection inlier limit [px]");
	v.integer("seed", seed, 0, 4294967295L,
	          "RANSAC random seed (results are repeatable)");
}

void TranslationParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	readOptions(*this, cfg, section);
}

void OdometryParams::describe(OptionVisitor& v)
{
	v.choice("mode", mode,
	         "imu: rotation from the attitude filter, translation from "
	         "vision (the paper); vision: full SE(3) from the tracks");
	v.flag("gyro_aid", gyro_aid,
	       "seed KLT with the gyro-predicted feature positions");
	v.integer("min_tracks", min_tracks, 3, 1000000,
	          "fewer 3D matches: the frame is flagged");
	v.real("attitude_blend", attitude_blend, 0, 1,
	       "mode = imu: fraction of the difference to the filter's attitude "
	       "R_WC is pulled by per frame");
	v.flag("follow_converging_attitude", follow_converging_attitude,
	       "mode = imu: R_WC follows the filter while it converges "
	       "(docs/ego.md)");
}

void OdometryParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	readOptions(*this, cfg, section);
}

void InertialParams::describe(OptionVisitor& v)
{
	v.flag("enable", enable,
	       "depth-inertial translation: the IMU predicts each frame's "
	       "position, the alignment corrects what the depth constrains");
	v.real("acc_noise_density", acc_noise_density, 1e-5, 10,
	       "accelerometer white noise as the filter sees it [m/s^2/sqrt(Hz)]");
	v.real("acc_bias_walk", acc_bias_walk, 0, 1,
	       "accelerometer bias random walk [m/s^3/sqrt(Hz)]");
	v.real("gravity_walk", gravity_walk, 0, 1,
	       "random walk of gravity in the odometry's world [m/s^2/sqrt(s)]");
	v.real("motion_accel_density", motion_accel_density, 1e-3, 100,
	       "without accelerometer samples: a hand-held camera's random "
	       "acceleration [m/s^2/sqrt(Hz)]");
	v.real("init_velocity_sigma", init_velocity_sigma, 1e-3, 100,
	       "velocity uncertainty at the first frame [m/s]");
	v.real("init_acc_bias_sigma", init_acc_bias_sigma, 1e-4, 10,
	       "accelerometer bias uncertainty at the first frame [m/s^2]");
	v.real("init_gravity_sigma", init_gravity_sigma, 1e-4, 10,
	       "gravity uncertainty at the first frame [m/s^2]");
	v.real("alignment_information_scale", alignment_information_scale, 1e-6, 1,
	       "the alignment's information is scaled by this (its points' "
	       "errors are not independent)");
	v.real("degenerate_sigma_m", degenerate_sigma_m, 1e-5, 10,
	       "a direction the depth pins to worse than this in one frame is "
	       "degenerate [m]");
	v.real("degenerate_ratio", degenerate_ratio, 0, 1,
	       "... or whose information is below this share of the best-known "
	       "direction's (0: off)");
	v.real("gate_sigma", gate_sigma, 1, 100,
	       "an alignment whose innovation lies beyond this many standard "
	       "deviations is refused");
	v.real("accel_range_ms2", accel_range_ms2, 1, 10000,
	       "accelerometer samples with a component at or beyond this are "
	       "saturated and left out [m/s^2]");
}

void InertialParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	readOptions(*this, cfg, section);
}

void AnchorParams::describe(OptionVisitor& v)
{
	v.flag("enable", enable,
	       "map-anchored tracking (false: frame-to-frame egomotion only)");
	v.integer("finest_level", finest_level, 0, 6,
	          "finest pyramid level aligned (0 = full size)");
	v.integer("coarsest_level", coarsest_level, 0, 6,
	          "coarsest pyramid level aligned");
	v.rule(coarsest_level >= finest_level, "coarsest_level",
	       "must be >= finest_level");
	v.integer("iterations", iterations, 1, 100,
	          "Levenberg-Marquardt steps per level (max)");
	v.integer("stride_px", stride_px, 1, 16,
	          "pixel sampling step at the finest level");
	v.real("geo_sigma_m", geo_sigma_m, 1e-5, 1,
	       "geometric residual scale, a of a + b z^2 [m]");
	v.real("geo_sigma_z2", geo_sigma_z2, 0, 1, "b of a + b z^2 [1/m]");
	v.real("gate_m", gate_m, 1e-3, 10,
	       "depth difference beyond a + b z^2 is not associated, a [m]");
	v.real("gate_z2", gate_z2, 0, 10, "b of the gate [1/m]");
	v.real("photo_sigma_grey", photo_sigma_grey, 0.01, 255,
	       "least photometric residual scale [grey levels]");
	v.real("photo_weight", photo_weight, 0, 100,
	       "weight of the photometric term (0: off)");
	v.real("tukey_c", tukey_c, 1, 100, "Tukey biweight limit [scales]");
	v.real("rotation_prior_sigma_deg", rotation_prior_sigma_deg, 0, 180,
	       "mode = imu: std. dev. of the IMU rotation prior (0: translation "
	       "only) [deg]");
	v.integer("min_inliers", min_inliers, 6, 10000000,
	          "fewer inliers at the finest level: failed");
	v.real("min_inlier_fraction", min_inlier_fraction, 0, 1,
	       "smaller share of inliers among associated points: failed");
	v.real("max_correction_m", max_correction_m, 1e-4, 100,
	       "anchored pose farther from the frame-to-frame one: rejected [m]");
	v.real("max_correction_deg", max_correction_deg, 1e-3, 180,
	       "... or turned more than this: rejected [deg]");
	v.real("relocalise_inlier_fraction", relocalise_inlier_fraction, 0, 1.01,
	       "... unless the inlier fraction is at least this");
	v.real("relocalise_overlap", relocalise_overlap, 0, 1.01,
	       "... and the overlap (inliers / points) at least this");
	v.real("keyframe_distance_m", keyframe_distance_m, 0.001, 100,
	       "new keyframe beyond this distance from the keyframe [m]");
	v.real("keyframe_angle_deg", keyframe_angle_deg, 0.01, 180,
	       "... or this angle [deg]");
	v.real("keyframe_min_overlap", keyframe_min_overlap, 0, 1,
	       "... or when the keyframe covers less than this of the points; "
	       "an alignment with fewer of them inliers also tries the other "
	       "keyframes");
	v.integer("max_keyframes", max_keyframes, 1, 100000,
	          "oldest keyframes dropped beyond this");
	v.integer("lost_frames", lost_frames, 1, 1000000,
	          "frames in a row without an accepted alignment: new keyframe "
	          "(lost)");
	v.real("max_excluded_fraction", max_excluded_fraction, 0, 1,
	       "a moving mask covering more than this share is not used");
	v.flag("predict_mask", predict_mask,
	       "predict the previous moving mask into the frame");
	v.integer("mask_margin_px", mask_margin_px, 0, 100,
	          "growth of the predicted mask [px]");
	v.real("mask_veto_consistent", mask_veto_consistent, 0, 1,
	       "a region of the fed-back mask whose aligned samples lay on the "
	       "static surface at least this often is not used (0: off)");
	v.real("min_depth_m", min_depth_m, 0, 100,
	       "depth below this is unused [m]");
	v.real("max_depth_m", max_depth_m, 0.01, 1000,
	       "depth above this is unused [m]");
	v.rule(max_depth_m > min_depth_m, "max_depth_m",
	       "must be greater than min_depth_m");
}

void AnchorParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section)
{
	readOptions(*this, cfg, section);
}

void EgoConfig::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                   bool requireCalibration)
{
	attitude.loadFromConfigFile(cfg);
	tracker.loadFromConfigFile(cfg);
	translation.loadFromConfigFile(cfg);
	odometry.loadFromConfigFile(cfg);
	anchor.loadFromConfigFile(cfg);
	inertial.loadFromConfigFile(cfg);
	SensorConfig::loadFromConfigFile(
	    cfg, requireCalibration && odometry.mode == OdometryMode::Imu);
}

void EgoConfig::loadFromFile(const std::string& given)
{
	const std::string path = resolvePreset(given);  // "stray.ini": a preset
	if (!mrpt::system::fileExists(path))
		throw ConfigFileMissing(path + ": no such config file" +
		                        presetHint(path));
	const auto cfg = bims::openIniFile(path);
	checkExperimentSections(*cfg);
	loadFromConfigFile(*cfg, false);
}

}  // namespace bims::ego
