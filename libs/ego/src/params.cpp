#include <bims/common/app.h>
#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/ego/params.h>
#include <bims/ego/so3.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/filesystem.h>

#include <Eigen/SVD>

#include <cmath>
#include <sstream>

namespace bims::ego
{
Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& M)
{
	Eigen::JacobiSVD<Eigen::Matrix3d> svd(
	    M, Eigen::ComputeFullU | Eigen::ComputeFullV);
	Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
	if (R.determinant() < 0)
	{
		Eigen::Matrix3d U = svd.matrixU();
		U.col(2) *= -1;
		R = U * svd.matrixV().transpose();
	}
	return R;
}

void AttitudeParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	ConfigSection s(cfg, section);
	kp = s.getDouble("kp", kp, 0, 100);
	ki = s.getDouble("ki", ki, 0, 100);
	kp_init = s.getDouble("kp_init", kp_init, 0, 1000);
	init_time_s = s.getDouble("init_time_s", init_time_s, 0, 3600);
	use_magnetometer = s.getBool("use_magnetometer", use_magnetometer);
	use_sensor_orientation =
	    s.getBool("use_sensor_orientation", use_sensor_orientation);
	gravity = s.getDouble("gravity", gravity, 9.7, 9.9);
	accel_gate = s.getDouble("accel_gate", accel_gate, 0, 100);
	accel_angle_gate_deg =
	    s.getDouble("accel_angle_gate_deg", accel_angle_gate_deg, 0, 180);
	accel_gate_max_s =
	    s.getDouble("accel_gate_max_s", accel_gate_max_s, 0, 3600);
	mag_norm_gate = s.getDouble("mag_norm_gate", mag_norm_gate, 0, 10);
	mag_dip_gate_deg =
	    s.getDouble("mag_dip_gate_deg", mag_dip_gate_deg, 0, 180);
	mag_heading_gate_deg =
	    s.getDouble("mag_heading_gate_deg", mag_heading_gate_deg, 0, 180);
	mag_gate_max_s = s.getDouble("mag_gate_max_s", mag_gate_max_s, 0, 1e6);
	kp_mag = s.getDouble("kp_mag", kp_mag, 0, 100);
	mag_reference =
	    s.getEnum("mag_reference", mag_reference, {"auto", "fixed"});
	mag_reference_samples = static_cast<int>(
	    s.getInt("mag_reference_samples", mag_reference_samples, 1, 100000));
	mag_norm = s.getDouble("mag_norm", mag_norm, 1e-9, 1e9);
	mag_dip_deg = s.getDouble("mag_dip_deg", mag_dip_deg, -90, 90);
	max_gap_s = s.getDouble("max_gap_s", max_gap_s, 1e-4, 100);
	history_s = s.getDouble("history_s", history_s, 0.1, 3600);
	s.finish();
}

void TrackerParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                       const std::string& section)
{
	ConfigSection s(cfg, section);
	max_features =
	    static_cast<int>(s.getInt("max_features", max_features, 8, 100000));
	grid_cols = static_cast<int>(s.getInt("grid_cols", grid_cols, 1, 100));
	grid_rows = static_cast<int>(s.getInt("grid_rows", grid_rows, 1, 100));
	min_distance_px = s.getDouble("min_distance_px", min_distance_px, 1, 1000);
	detector = s.getEnum("detector", detector, {"fast", "gftt"});
	fast_threshold =
	    static_cast<int>(s.getInt("fast_threshold", fast_threshold, 1, 255));
	gftt_quality = s.getDouble("gftt_quality", gftt_quality, 1e-6, 1);
	window = static_cast<int>(s.getInt("window", window, 5, 101));
	if (window % 2 == 0) s.fail("window", "must be odd");
	pyramid_levels =
	    static_cast<int>(s.getInt("pyramid_levels", pyramid_levels, 0, 8));
	max_iterations =
	    static_cast<int>(s.getInt("max_iterations", max_iterations, 1, 1000));
	epsilon = s.getDouble("epsilon", epsilon, 1e-6, 10);
	fb_threshold_px =
	    s.getDouble("fb_threshold_px", fb_threshold_px, 0.01, 100);
	border_px = s.getDouble("border_px", border_px, 0, 200);
	mask_dilate_px =
	    static_cast<int>(s.getInt("mask_dilate_px", mask_dilate_px, 0, 200));
	s.finish();
}

void TranslationParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	ConfigSection s(cfg, section);
	method = s.getEnum("method", method, {"ransac", "lmeds"});
	iterations = static_cast<int>(s.getInt("iterations", iterations, 1, 1e6));
	vision_iterations = static_cast<int>(
	    s.getInt("vision_iterations", vision_iterations, 1, 1e6));
	inlier_threshold_m =
	    s.getDouble("inlier_threshold_m", inlier_threshold_m, 1e-5, 10);
	inlier_threshold_z2 =
	    s.getDouble("inlier_threshold_z2", inlier_threshold_z2, 0, 10);
	min_inliers =
	    static_cast<int>(s.getInt("min_inliers", min_inliers, 3, 100000));
	min_depth_m = s.getDouble("min_depth_m", min_depth_m, 0, 100);
	max_depth_m = s.getDouble("max_depth_m", max_depth_m, 0.01, 1000);
	if (max_depth_m <= min_depth_m)
		s.fail("max_depth_m", "must be greater than min_depth_m");
	refine = s.getEnum("refine", refine, {"none", "se3"});
	rotation_prior_sigma_deg = s.getDouble("rotation_prior_sigma_deg",
	                                       rotation_prior_sigma_deg, 1e-4, 180);
	point_sigma_m = s.getDouble("point_sigma_m", point_sigma_m, 1e-6, 10);
	reprojection = s.getBool("reprojection", reprojection);
	reprojection_sigma_px =
	    s.getDouble("reprojection_sigma_px", reprojection_sigma_px, 1e-3, 100);
	reprojection_threshold_px = s.getDouble(
	    "reprojection_threshold_px", reprojection_threshold_px, 0.1, 1000);
	seed = static_cast<uint32_t>(s.getInt("seed", seed, 0, 4294967295L));
	s.finish();
}

void OdometryParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	ConfigSection s(cfg, section);
	mode = s.getEnum("mode", mode, {"imu", "vision"});
	gyro_aid = s.getBool("gyro_aid", gyro_aid);
	min_tracks = static_cast<int>(s.getInt("min_tracks", min_tracks, 3, 1e6));
	attitude_blend = s.getDouble("attitude_blend", attitude_blend, 0, 1);
	follow_converging_attitude =
	    s.getBool("follow_converging_attitude", follow_converging_attitude);
	s.finish();
}

void AnchorParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section)
{
	ConfigSection s(cfg, section);
	enable = s.getBool("enable", enable);
	finest_level =
	    static_cast<int>(s.getInt("finest_level", finest_level, 0, 6));
	coarsest_level =
	    static_cast<int>(s.getInt("coarsest_level", coarsest_level, 0, 6));
	if (coarsest_level < finest_level)
		s.fail("coarsest_level", "must be >= finest_level");
	iterations = static_cast<int>(s.getInt("iterations", iterations, 1, 100));
	stride_px = static_cast<int>(s.getInt("stride_px", stride_px, 1, 16));
	geo_sigma_m = s.getDouble("geo_sigma_m", geo_sigma_m, 1e-5, 1);
	geo_sigma_z2 = s.getDouble("geo_sigma_z2", geo_sigma_z2, 0, 1);
	gate_m = s.getDouble("gate_m", gate_m, 1e-3, 10);
	gate_z2 = s.getDouble("gate_z2", gate_z2, 0, 10);
	photo_sigma_grey =
	    s.getDouble("photo_sigma_grey", photo_sigma_grey, 0.01, 255);
	photo_weight = s.getDouble("photo_weight", photo_weight, 0, 100);
	tukey_c = s.getDouble("tukey_c", tukey_c, 1, 100);
	rotation_prior_sigma_deg = s.getDouble("rotation_prior_sigma_deg",
	                                       rotation_prior_sigma_deg, 0, 180);
	min_inliers =
	    static_cast<int>(s.getInt("min_inliers", min_inliers, 6, 10000000));
	min_inlier_fraction =
	    s.getDouble("min_inlier_fraction", min_inlier_fraction, 0, 1);
	max_correction_m =
	    s.getDouble("max_correction_m", max_correction_m, 1e-4, 100);
	max_correction_deg =
	    s.getDouble("max_correction_deg", max_correction_deg, 1e-3, 180);
	relocalise_inlier_fraction = s.getDouble(
	    "relocalise_inlier_fraction", relocalise_inlier_fraction, 0, 1.01);
	relocalise_overlap =
	    s.getDouble("relocalise_overlap", relocalise_overlap, 0, 1.01);
	keyframe_distance_m =
	    s.getDouble("keyframe_distance_m", keyframe_distance_m, 0.001, 100);
	keyframe_angle_deg =
	    s.getDouble("keyframe_angle_deg", keyframe_angle_deg, 0.01, 180);
	keyframe_min_overlap =
	    s.getDouble("keyframe_min_overlap", keyframe_min_overlap, 0, 1);
	max_keyframes =
	    static_cast<int>(s.getInt("max_keyframes", max_keyframes, 1, 100000));
	lost_frames =
	    static_cast<int>(s.getInt("lost_frames", lost_frames, 1, 1e6));
	max_excluded_fraction =
	    s.getDouble("max_excluded_fraction", max_excluded_fraction, 0, 1);
	predict_mask = s.getBool("predict_mask", predict_mask);
	mask_margin_px =
	    static_cast<int>(s.getInt("mask_margin_px", mask_margin_px, 0, 100));
	min_depth_m = s.getDouble("min_depth_m", min_depth_m, 0, 100);
	max_depth_m = s.getDouble("max_depth_m", max_depth_m, 0.01, 1000);
	if (max_depth_m <= min_depth_m)
		s.fail("max_depth_m", "must be greater than min_depth_m");
	s.finish();
}

void CalibrationParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section,
    bool requireR)
{
	ConfigSection s(cfg, section);
	has_R_IC = s.has("R_IC");
	if (!has_R_IC && requireR)
		s.fail("R_IC",
		       "missing: the IMU-to-camera rotation (9 reals, row major, p_I = "
		       "R_IC p_C) is needed when [odometry] mode = imu");
	if (has_R_IC)
	{
		const auto v = s.getDoubles("R_IC", {}, 9, -1.0001, 1.0001);
		Eigen::Matrix3d M;
		M << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
		const double err =
		    (M * M.transpose() - Eigen::Matrix3d::Identity()).norm();
		if (err > 1e-3 || M.determinant() < 0)
		{
			std::ostringstream os;
			os << "not a rotation matrix (|R R^T - I| = " << err
			   << ", det = " << M.determinant() << ")";
			s.fail("R_IC", os.str());
		}
		R_IC = orthonormalize(M);
	}
	time_offset_s = s.getDouble("time_offset_s", time_offset_s, -10, 10);
	s.finish();
}

void CameraParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section)
{
	ConfigSection s(cfg, section);
	const char* keys[] = {"fx", "fy", "cx", "cy", "width", "height"};
	int n = 0;
	for (const char* k : keys) n += s.has(k) ? 1 : 0;
	if (n > 0 && n < 6)
		for (const char* k : keys)
			if (!s.has(k))
				s.fail(k,
				       "missing: give all of fx fy cx cy width height, "
				       "or none to use the observations' own intrinsics");
	given = (n == 6);
	if (given)
	{
		fx = s.requireDouble("fx", 1, 1e5);
		fy = s.requireDouble("fy", 1, 1e5);
		cx = s.requireDouble("cx", -1e5, 1e5);
		cy = s.requireDouble("cy", -1e5, 1e5);
		width = static_cast<int>(s.requireInt("width", 1, 100000));
		height = static_cast<int>(s.requireInt("height", 1, 100000));
	}
	// Keys other modules read from the same section.
	s.allow("depth_scale");
	s.allow("max_range");
	s.allow("depth_units");
	s.allow("k1");
	s.allow("k2");
	s.allow("p1");
	s.allow("p2");
	s.allow("k3");
	s.finish();
}

void SensorsParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                       const std::string& section)
{
	ConfigSection s(cfg, section);
	rgbd_label = s.getString("rgbd_label", rgbd_label);
	imu_label = s.getString("imu_label", imu_label);
	s.allow("rgbd_rate_hz");  // informative keys written by bims-sim
	s.allow("imu_rate_hz");
	s.finish();
}

void EgoConfig::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                   bool requireCalibration)
{
	attitude.loadFromConfigFile(cfg);
	tracker.loadFromConfigFile(cfg);
	translation.loadFromConfigFile(cfg);
	odometry.loadFromConfigFile(cfg);
	anchor.loadFromConfigFile(cfg);
	depth_correction.loadFromConfigFile(cfg);
	calibration.loadFromConfigFile(
	    cfg, "calibration", requireCalibration && odometry.mode == "imu");
	camera.loadFromConfigFile(cfg);
	sensors.loadFromConfigFile(cfg);
}

void EgoConfig::loadFromFile(const std::string& path)
{
	if (!mrpt::system::fileExists(path))
		throw UsageError(path + ": no such config file");
	bims::checkIniFile(path);
	mrpt::config::CConfigFile cfg(path);
	checkExperimentSections(cfg);
	loadFromConfigFile(cfg, false);
}

void EgoConfig::overrideSensorSections(const mrpt::config::CConfigFileBase& cal)
{
	if (cal.sectionExists("calibration")) calibration.loadFromConfigFile(cal);
	if (cal.sectionExists("camera")) camera.loadFromConfigFile(cal);
	if (cal.sectionExists("sensors")) sensors.loadFromConfigFile(cal);
	if (cal.sectionExists("depth_correction"))
		depth_correction.loadFromConfigFile(cal);
}

}  // namespace bims::ego
