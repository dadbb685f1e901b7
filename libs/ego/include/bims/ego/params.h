// Parameters of the egomotion stage, one plain struct per .ini section of the
// experiment file ([attitude], [tracker], [translation], [odometry],
// and the sensor rig's, bims/sensors/params.h; see bims/common/experiment.h).
//
// Each struct has defaults (config/default.ini's values: the built-in
// defaults are that file's model), describe() naming every key once
// (bims/common/options.h: reading, effective.ini, docs/config.md) and
// loadFromConfigFile(cfg, section), which reads through it: out-of-range
// values, bad choices and unknown keys are ConfigError naming the file, the
// section and the key. Derivations of the filter and the gating rules:
// docs/attitude.md; the rest: docs/ego.md.
#pragma once

#include <bims/common/choice.h>
#include <bims/common/options.h>
#include <bims/sensors/params.h>
#include <mrpt/config/CConfigFileBase.h>

#include <Eigen/Core>

#include <array>
#include <optional>
#include <string>

namespace bims::ego
{
/** [attitude] mag_reference: where the magnetometer's reference comes from. */
enum class MagReference
{
	Auto,  ///< norm and dip learnt from the first undisturbed samples
	Fixed  ///< mag_norm / mag_dip_deg
};
inline Choices<MagReference> choices(MagReference)
{
	static constexpr ChoiceName<MagReference> t[] = {
	    {MagReference::Auto, "auto"}, {MagReference::Fixed, "fixed"}};
	return t;
}

/** [tracker] detector: the corners new tracks start from. */
enum class FeatureDetector
{
	Fast,  ///< FAST corners
	Gftt   ///< OpenCV goodFeaturesToTrack (Shi-Tomasi)
};
inline Choices<FeatureDetector> choices(FeatureDetector)
{
	static constexpr ChoiceName<FeatureDetector> t[] = {
	    {FeatureDetector::Fast, "fast"}, {FeatureDetector::Gftt, "gftt"}};
	return t;
}

/** [translation] method: the robust estimator. */
enum class RobustMethod
{
	Ransac,  ///< most inliers
	Lmeds    ///< least median of squares
};
inline Choices<RobustMethod> choices(RobustMethod)
{
	static constexpr ChoiceName<RobustMethod> t[] = {
	    {RobustMethod::Ransac, "ransac"}, {RobustMethod::Lmeds, "lmeds"}};
	return t;
}

/** [translation] refine: what follows the robust estimate. */
enum class TranslationRefine
{
	None,  ///< the IMU rotation kept as it is
	SE3    ///< Gauss-Newton over R and t, the IMU rotation as a prior
};
inline Choices<TranslationRefine> choices(TranslationRefine)
{
	static constexpr ChoiceName<TranslationRefine> t[] = {
	    {TranslationRefine::None, "none"}, {TranslationRefine::SE3, "se3"}};
	return t;
}

/** [odometry] mode: where the rotation comes from. */
enum class OdometryMode
{
	Imu,    ///< rotation from the attitude filter, translation from vision
	Vision  ///< full SE(3) from the tracked 3D features
};
inline Choices<OdometryMode> choices(OdometryMode)
{
	static constexpr ChoiceName<OdometryMode> t[] = {
	    {OdometryMode::Imu, "imu"}, {OdometryMode::Vision, "vision"}};
	return t;
}

/** [attitude]: the accelerometer + magnetometer + gyro attitude filter. */
struct AttitudeParams
{
	double kp = 1.0;   ///< proportional correction gain [1/s]
	double ki = 0.25;  ///< gyro-bias integral gain [1/s^2] (critically damped
	                   ///< with kp = 1)
	double kp_init = 10.0;         ///< gain during the first init_time_s [1/s]
	double init_time_s = 1.0;      ///< fast-convergence phase length [s]
	bool use_magnetometer = true;  ///< false: heading from the gyro only
	/** true: take R_WI from the sensor's own orientation quaternion
	 * (IMU_ORI_QUAT_*, {W} = NWU) when present instead of filtering. */
	bool use_sensor_orientation = false;
	double gravity = 9.80665;  ///< local gravity magnitude [m/s^2]
	/** Accelerometer used only if | |f| - gravity | below this [m/s^2]. */
	double accel_gate = 0.8;
	/** ... and if the measured and predicted gravity directions differ by
	 * less than this [deg] (after the first init_time_s) ... */
	double accel_angle_gate_deg = 3.0;
	/** ... unless they have disagreed for longer than this [s]. */
	double accel_gate_max_s = 3.0;
	/** Magnetometer used only if | |m| / m_ref - 1 | below this [-]. */
	double mag_norm_gate = 0.08;
	/** ... and if |dip - dip_ref| below this [deg]. */
	double mag_dip_gate_deg = 4.0;
	/** ... and if its heading innovation is below this [deg] (after the
	 * first init_time_s), unless that has lasted mag_gate_max_s [s]. */
	double mag_heading_gate_deg = 10.0;
	double mag_gate_max_s = 20.0;
	/** Heading correction gain [1/s] (slower than tilt: the field is the
	 * less trustworthy reference). */
	double kp_mag = 0.5;
	/** Reference field: "auto" learns norm and dip from the first
	 * mag_reference_samples undisturbed-looking samples; "fixed" uses
	 * mag_norm / mag_dip_deg. */
	MagReference mag_reference = MagReference::Auto;
	int mag_reference_samples = 50;
	double mag_norm = 1.0;      ///< reference |m| (sensor units), when fixed
	double mag_dip_deg = 60.0;  ///< reference dip below horizontal [deg]
	/** A gap between IMU samples longer than this is flagged [s]. */
	double max_gap_s = 0.1;
	double history_s = 10.0;  ///< attitude history kept for queries [s]

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "attitude");
};

/** [tracker]: the gyro-aided pyramidal KLT tracker. */
struct TrackerParams
{
	int max_features = 200;       ///< features kept per frame
	int grid_cols = 8;            ///< replenishment grid (columns)
	int grid_rows = 6;            ///< replenishment grid (rows)
	double min_distance_px = 12;  ///< min spacing of new features [px]
	FeatureDetector detector = FeatureDetector::Fast;
	int fast_threshold = 15;       ///< FAST intensity threshold [grey levels]
	double gftt_quality = 0.01;    ///< goodFeaturesToTrack quality level
	int window = 15;               ///< LK window side [px] (odd)
	int pyramid_levels = 2;        ///< LK max pyramid level (0 = none); small
	                               ///< because the gyro aid gives a close guess
	int max_iterations = 30;       ///< LK iterations per level
	double epsilon = 0.01;         ///< LK convergence [px]
	double fb_threshold_px = 1.0;  ///< forward-backward error limit [px]
	double border_px = 8;    ///< tracks closer to the border are dropped [px]
	int mask_dilate_px = 8;  ///< growth of the moving-region mask [px]

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "tracker");
};

/** [translation]: robust translation (and optional SE(3) refinement). */
struct TranslationParams
{
	RobustMethod method = RobustMethod::Ransac;
	int iterations = 60;  ///< hypotheses for the 1-point translation model
	int vision_iterations = 200;  ///< hypotheses for the 3-point SE(3) model
	/** Inlier threshold on the 3D residual: a + b z^2 [m], z = depth [m]. */
	double inlier_threshold_m = 0.02;
	double inlier_threshold_z2 = 0.01;  ///< b above [1/m]
	int min_inliers = 8;       ///< fewer inliers: frame flagged as failed
	double min_depth_m = 0.3;  ///< depth readings outside [min,max] unused
	double max_depth_m = 8.0;
	/** Refinement of R and t over the inliers (TranslationRefine). */
	TranslationRefine refine = TranslationRefine::None;
	double rotation_prior_sigma_deg = 0.3;  ///< IMU rotation std. dev. [deg]
	double point_sigma_m = 0.01;  ///< 3D residual std. dev. at 1 m [m]
	/** Final reprojection refinement of the robust 3D estimate (t only in
	 * mode = imu, R and t in mode = vision). */
	bool reprojection = true;
	double reprojection_sigma_px = 0.7;      ///< pixel noise (Huber scale) [px]
	double reprojection_threshold_px = 3.0;  ///< inlier limit [px]
	uint32_t seed = 1;  ///< RANSAC random seed (results are repeatable)

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "translation");
};

/** [odometry]: where the rotation comes from and whether the gyro aids. */
struct OdometryParams
{
	/** Imu: rotation from the attitude filter, translation from vision
	 * (the paper); Vision: full SE(3) from the tracked 3D features. */
	OdometryMode mode = OdometryMode::Imu;
	/** Seed KLT with the gyro-predicted feature positions (when IMU data
	 * exist; otherwise with the previous frame's rotation rate). */
	bool gyro_aid = true;
	int min_tracks = 12;  ///< fewer 3D matches: frame flagged
	/** mode = imu: the inter-frame rotation comes from the gyro alone and
	 * the absolute R_WC is pulled towards the attitude filter's by this
	 * fraction of their difference per frame [0..1] (1 = R_WC is the
	 * filter's, with its correction noise in every inter-frame rotation). */
	double attitude_blend = 0.002;
	/** mode = imu, while the attitude filter converges (its first
	 * init_time_s): true, the absolute R_WC follows the filter (gravity and
	 * north from the start, but every frame of that phase registers the
	 * scene with the filter's convergence in it); false, R_WC keeps
	 * integrating the gyro from the filter's first attitude and the blend
	 * waits for the convergence, so the map stays consistent under fast
	 * rotation (docs/ego.md). */
	bool follow_converging_attitude = false;

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "odometry");
};

/** [inertial]: the depth-inertial translation (InertialFilter,
 * docs/ego.md "Depth-inertial translation"). With accelerometer samples
 * (mode = imu) the camera's position, velocity, the accelerometer's bias
 * and gravity are filtered: the IMU predicts each frame's position and its
 * uncertainty, the keyframe alignment takes that as its prior and measures
 * what the depth constrains; what it does not constrain (a blank wall, a
 * corridor, glass) keeps the inertial prediction. The noise figures are a
 * phone's or a robot's MEMS IMU held in a hand, with the rotation's and the
 * clock's errors folded in. */
struct InertialParams
{
	/** false (the default): the translation as before (the frame-to-frame
	 * and constant-velocity guesses, no inertial prior). On for the phone
	 * captures (config/stray.ini); on the simulator's depth-only sample it
	 * still costs (ATE 0.015 -> 0.027 m: docs/ego.md). */
	bool enable = false;
	/** Accelerometer white noise as the filter sees it [m/s^2/sqrt(Hz)]:
	 * the sensor's own (~0.002 on a phone) is the least of it; the
	 * rotation it is turned into the world with (R_IC known to a few
	 * degrees on a phone: 0.5 m/s^2 of gravity), the lever arm and the
	 * clock add far more (measured on the phone captures: docs/ego.md). */
	double acc_noise_density = 0.2;
	double acc_bias_walk = 1e-3;  ///< bias random walk [m/s^3/sqrt(Hz)]
	/** Random walk of gravity in the odometry's world [m/s^2/sqrt(s)] (the
	 * attitude blend turns that world slowly). */
	double gravity_walk = 5e-3;
	/** Where no accelerometer sample covers an interval (a gap, an IMU that
	 * stopped): constant velocity with a hand-held camera's random
	 * acceleration of this density [m/s^2/sqrt(Hz)]. */
	double motion_accel_density = 1.0;
	double init_velocity_sigma = 0.5;  ///< at the first frame [m/s]
	double init_acc_bias_sigma = 0.1;  ///< [m/s^2] per axis
	double init_gravity_sigma = 0.3;   ///< [m/s^2] per axis (~2 deg tilt)
	/** The alignment's information (its normal equations over the sampled
	 * points, residuals in their noise's units) times this: neighbouring
	 * points' errors are not independent (a keyframe's error is shared by
	 * all its points). */
	double alignment_information_scale = 0.3;
	/** A direction of the position the depth pins to worse than this in
	 * one frame is degenerate (the frame is flagged) [m]. */
	double degenerate_sigma_m = 0.05;
	/** ... or whose information is below this share of the best-known
	 * direction's (a flat wall's noisy normals give its in-plane directions
	 * ~0.02 of the normal's). 0: off, the default: on the phone captures a
	 * weak direction still carries information the IMU alone cannot replace
	 * for long (docs/ego.md). */
	double degenerate_ratio = 0;
	/** An alignment whose innovation over the directions it constrains lies
	 * beyond this many standard deviations (chi-square of their number) is
	 * refused: the prediction stands (flagged inertial_rejected). */
	double gate_sigma = 5;
	/** Accelerometer samples with a component at or beyond this are
	 * saturated and left out (the motion prior covers them) [m/s^2]; 8 g. */
	double accel_range_ms2 = 78.0;

	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "inertial");
};

/** [anchor]: map-anchored tracking. Each frame is aligned densely
 * (point-to-plane ICP + photometric, robust Tukey weights, coarse to fine) to
 * a keyframe of the static scene registered in the same world, starting from
 * the frame-to-frame estimate; content absent from the keyframe (people who
 * walked in, or moved) gets no weight (docs/ego.md, "Map-anchored tracking").
 */
struct AnchorParams
{
	bool enable = true;    ///< false: frame-to-frame egomotion only
	int finest_level = 1;  ///< finest pyramid level aligned (0 = full size)
	/** Coarsest level (each level halves the size; 2 = 160x120 for VGA:
	 * the frame-to-frame guess is close, a coarser start only costs). */
	int coarsest_level = 2;
	int iterations = 4;  ///< Levenberg-Marquardt steps per level (max)
	/** Pixel sampling step at the finest level (half that a level up...,
	 * so that every level has about as many samples). */
	int stride_px = 4;
	/** Geometric residual scale a + b z^2 [m] (point-to-plane). */
	double geo_sigma_m = 0.004;
	double geo_sigma_z2 = 0.004;  ///< b above [1/m]
	/** A point whose depth differs from the keyframe's at its pixel by
	 * more than a + b z^2 is not associated (occlusion, moving) [m]. */
	double gate_m = 0.08;
	double gate_z2 = 0.02;  ///< b above [1/m]
	/** Least photometric residual scale [grey levels]; the scale used is
	 * 1.4826 x the median |residual| of the last pass when larger. */
	double photo_sigma_grey = 8;
	double photo_weight = 1;  ///< weight of the photometric term (0: off)
	double tukey_c = 4.685;   ///< Tukey biweight limit [scales]
	/** mode = imu: std. dev. of the IMU rotation as the alignment's prior
	 * [deg]; 0 keeps the IMU rotation and aligns the translation only (the
	 * paper's split, but the gyro's drift then stays in the map). */
	double rotation_prior_sigma_deg = 0.02;
	/** Fewer inliers at the finest level: failed (of ~4800 samples at
	 * 640x480 with stride_px 4; people may cover 70 % of them). */
	int min_inliers = 150;
	/** Fewer than this share of the associated points inliers: failed. */
	double min_inlier_fraction = 0.3;
	/** Anchored pose farther than this from the frame-to-frame one: the
	 * alignment is rejected (flagged, frame-to-frame kept) [m], [deg]. */
	double max_correction_m = 0.15;
	double max_correction_deg = 6;
	/** ... unless the frame fits the keyframe almost entirely: inlier
	 * fraction and overlap (inliers / points) at least these. Then the
	 * pose had drifted and is corrected (flagged anchor_relocalised). */
	double relocalise_inlier_fraction = 0.97;
	double relocalise_overlap = 0.35;
	/** A new keyframe when the frame is farther than this from its
	 * keyframe [m], [deg], or when the keyframe covers less than
	 * keyframe_min_overlap of its points (occluders count as covered).
	 * An accepted alignment with less than keyframe_min_overlap of the
	 * frame's points inliers also tries the other keyframes (the newest,
	 * the next nearest), and the one with the most inliers anchors the
	 * frame (KeyframeAnchor::track). */
	double keyframe_distance_m = 0.3;
	double keyframe_angle_deg = 15;
	double keyframe_min_overlap = 0.5;
	int max_keyframes = 64;  ///< oldest dropped beyond this
	/** After this many frames in a row without an accepted alignment the
	 * current frame becomes the keyframe (tracking lost, flagged). */
	int lost_frames = 10;
	/** A moving mask that covers more than this share of a frame is not
	 * used for that frame (flagged mask_ignored). Below it, an alignment
	 * that fails with the mask is tried once more without it (flagged the
	 * same): the feedback must not starve the alignment. 0.9: a correct
	 * mask over 70-89 % of the view (simulator preset occluder) is what
	 * keeps the pose on the static scene (docs/ego.md). */
	double max_excluded_fraction = 0.9;
	/** true: the previous frame's moving mask is predicted into the frame
	 * (its masked readings moved with the predicted motion and projected:
	 * moving_prediction.h) before it excludes pixels from the alignment
	 * and from the keyframe the frame may become; false: the previous mask
	 * is used as it is. Off by default: measured no better on the Bonn
	 * slice and the presets, and worse on one (docs/journal/egomotion.md). */
	bool predict_mask = false;
	/** The predicted mask grows by this many pixels a side (the movers' own
	 * motion between two frames, the prediction's error) [px]. */
	int mask_margin_px = 4;
	/** The geometry's veto of the fed-back moving mask: a connected region
	 * of the previous frame's mask is not used (not excluded from the
	 * alignment, not dropped from the keyframe) when at least this share
	 * of its aligned samples lay on the static keyframe's surface in that
	 * frame's accepted alignment: what the alignment found static is not
	 * left out because a tier called it moving (flagged mask_vetoed).
	 * 0: off. docs/ego.md, "The fed-back mask". */
	double mask_veto_consistent = 0.5;
	double min_depth_m = 0.3;  ///< depth outside [min,max] unused [m]
	double max_depth_m = 6.0;

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "anchor");
};

/** The sensor rig's sections (bims/sensors/params.h), used throughout the
 * egomotion under these names. */
using sensors::CalibrationParams;
using sensors::CameraParams;
using sensors::DepthCorrectionParams;
using sensors::kDepthCorrectionTerms;
using sensors::SensorsParams;

/** Everything the egomotion stage reads from one experiment file: the
 * sensor rig's sections (depth_correction, calibration, camera, sensors)
 * and its own. */
struct EgoConfig : sensors::SensorConfig
{
	AttitudeParams attitude;
	TrackerParams tracker;
	TranslationParams translation;
	OdometryParams odometry;
	AnchorParams anchor;
	InertialParams inertial;

	/** Reads all sections above (each optional, defaults otherwise);
	 * R_IC is required when odometry.mode = imu and \a requireCalibration
	 * (false: the caller reads [calibration] from another file later). */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        bool requireCalibration = true);

	/** Opens the experiment file \a path, checks its sections and reads
	 * it (loadFromConfigFile(cfg, false)); a missing file is a
	 * bims::ConfigFileMissing naming it. */
	void loadFromFile(const std::string& path);
};

}  // namespace bims::ego
