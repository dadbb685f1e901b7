// The sensor rig's sections of an experiment .ini: which observations of a
// rawlog are the RGB-D camera and the IMU ([sensors]), the camera's
// intrinsics ([camera]), the IMU-camera extrinsics and clock offset
// ([calibration]) and the depth sensor's smooth distortion
// ([depth_correction]). Everything that reads a recording needs them (the
// frame source, the egomotion, the calibrations), so they live below the
// egomotion: bims/ego/params.h builds its EgoConfig on SensorConfig.
//
// Each struct has defaults, describe() naming every key once
// (bims/common/options.h: reading, effective.ini, docs/config.md) and
// loadFromConfigFile(cfg, section); out-of-range values and unknown keys are
// ConfigError naming the file, the section and the key.
#pragma once

#include <bims/common/options.h>
#include <mrpt/config/CConfigFileBase.h>

#include <Eigen/Core>

#include <array>
#include <string>

namespace bims::sensors
{
/** [calibration]: IMU-camera extrinsics. Convention (bims/common/frames.h):
 * R_IC is the camera frame {C} (optical) expressed in the IMU frame {I}:
 * p_I = R_IC p_C, so R_WC = R_WI R_IC. Time: the IMU sample stamped
 * t_cam + time_offset_s was taken at the instant of the camera frame stamped
 * t_cam. */
struct CalibrationParams
{
	/** The simulator's mounting (config/default.ini): IMU x forward, y
	 * left, z up on the camera's optical axes. */
	Eigen::Matrix3d R_IC =
	    (Eigen::Matrix3d() << 0, 0, 1, -1, 0, 0, 0, -1, 0).finished();
	/** R_IC is known: the built-in one, or read from a file that gives it
	 * (a file without R_IC leaves it unknown: no IMU rotation). */
	bool has_R_IC = true;
	double time_offset_s = 0;  ///< t_imu = t_cam + time_offset_s [s]

	/** Keys: R_IC = 9 reals, row major (checked orthonormal to 1e-3, then
	 * re-orthonormalised); time_offset_s. */
	void describe(OptionVisitor& v);
	/** \param requireR throws ConfigError naming file/section/key when the
	 * file gives no R_IC. */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "calibration",
	                        bool requireR = false);
};

/** [camera]: intrinsics; when the section has none, those of each
 * observation (cameraParamsIntensity) are used. */
struct CameraParams
{
	bool given = false;                     ///< fx..height present in the file
	double fx = 0, fy = 0, cx = 0, cy = 0;  ///< [px]
	int width = 0, height = 0;              ///< [px]

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "camera");
};

/** [sensors]: sensor labels in the rawlog (empty = accept any). */
struct SensorsParams
{
	std::string rgbd_label = "RGBD";
	std::string imu_label = "IMU";

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "sensors");
};

/** Terms of the depth correction polynomial (bims/sensors/depth_correction.h).
 */
constexpr int kDepthCorrectionTerms = 12;

/** [depth_correction]: a smooth multiplicative correction of the depth
 * readings, z (1 + delta(x, y)) (bims/sensors/depth_correction.h; fitted by
 * bims-calib-depth): enable, coefficients (12 reals). */
struct DepthCorrectionParams
{
	bool enable = false;
	std::array<double, kDepthCorrectionTerms> coefficients{};

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "depth_correction");
	/** The section as .ini text (what bims-calib-depth writes). */
	std::string toIni(const std::string& comment = "") const;
};

/** The sensor rig: every section above. */
struct SensorConfig
{
	DepthCorrectionParams depth_correction;
	CalibrationParams calibration;
	CameraParams camera;
	SensorsParams sensors;

	/** Reads the four sections (each optional, defaults otherwise);
	 * \a requireR_IC: a missing [calibration] R_IC is a ConfigError. */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        bool requireR_IC);

	/** Overrides the sections present in \a cal (e.g. bims-sim's
	 * OUT_gt/calibration.ini); sections absent from \a cal are left as
	 * they are. */
	void overrideSensorSections(const mrpt::config::CConfigFileBase& cal);
};

}  // namespace bims::sensors
