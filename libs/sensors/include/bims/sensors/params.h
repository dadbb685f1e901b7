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
#include <mrpt/img/TCamera.h>

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

/** The one camera model of bims: pinhole intrinsics of a depth image and
 * the image registered to it [px] (distortion ignored, as in MRPT's own
 * unprojection). K() is its matrix form for the egomotion's algebra,
 * tcamera() MRPT's for the flow tier; width = height = 0: no pinhole model
 * (an unorganised cloud). */
struct PinholeCamera
{
	int width = 0, height = 0;
	double fx = 0, fy = 0, cx = 0, cy = 0;

	bool operator==(const PinholeCamera& o) const
	{
		return width == o.width && height == o.height && fx == o.fx &&
		       fy == o.fy && cx == o.cx && cy == o.cy;
	}
	/** [fx 0 cx; 0 fy cy; 0 0 1]. */
	Eigen::Matrix3d K() const;
	/** The camera of matrix \a K for images of \a width x \a height. */
	static PinholeCamera fromK(const Eigen::Matrix3d& K, int width, int height);
	/** MRPT's camera parameters of the same model (no distortion). */
	mrpt::img::TCamera tcamera() const;
	/** The pinhole part of MRPT's camera parameters (distortion dropped). */
	static PinholeCamera of(const mrpt::img::TCamera& c);
};

/** [camera]: intrinsics; when the section has none, those of each
 * observation (cameraParamsIntensity) are used. */
struct CameraParams : PinholeCamera
{
	bool given = false;  ///< fx..height present in the file

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
