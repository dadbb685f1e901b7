// Simulated IMU (accelerometer, gyroscope, magnetometer, optional orientation)
// rigidly attached to the camera, with white noise and bias random walk.
//
// Frames and conventions:
//  - {I} IMU body frame, {C} camera optical frame, {W} world (z up, x north).
//  - R_IC is the orientation of {C} in {I}: p_I = R_IC * p_C (the project's
//    T_AB naming: frame B expressed in A). The default R_IC (ypr = -90, 0,
//    -90 deg) makes {I} = MRPT's scan frame (x forward, y left, z up) - an
//    Xsens mounted level on top of a Kinect.
//  - The IMU sits at the camera centre (no lever arm).
//  - Time offset: an IMU sample stamped t_stamp measured the motion at the
//    true time t_stamp - time_offset_s (positive = IMU stamps are late).
//  - Accelerometer: specific force f_I = R_IW (a_W - g_W) with
//    g_W = (0, 0, -9.80665); at rest it reads +9.81 along the {I} axis that
//    points up.
//  - Gyroscope: angular velocity of {I} w.r.t. {W}, in {I} [rad/s].
//  - Magnetometer: Earth field m_W (+ optional local disturbance) in {I}
//    [gauss]; m_W = B (cos dip cos decl, -cos dip sin decl, -sin dip) in NWU.
//  - Continuous-time noise densities; a sample at rate f gets white noise with
//    sigma = density * sqrt(f); biases random-walk,
//    b += sigma_rw * sqrt(dt) * N(0, 1).
#pragma once

#include <bims/io/trajectory.h>
#include <bims/sim/motion.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/obs/CObservationIMU.h>

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace bims::sim
{
/** [imu] and [calibration] parameters. Defaults: Xsens MTi-like MEMS. */
struct ImuParams
{
	double rateHz = 100;        ///< sample rate [Hz] (not a multiple of 30 fps)
	std::string label = "IMU";  ///< sensorLabel of the CObservationIMU
	// Gyroscope
	double gyroNoiseDensity =
	    8.7e-4;                  ///< [rad/s/sqrt(Hz)] (0.05 deg/s/sqrt(Hz))
	double gyroBiasRw = 2.0e-5;  ///< bias random walk [rad/s^2/sqrt(Hz)]
	double gyroBiasInit =
	    3.5e-3;  ///< sigma of the initial bias per axis [rad/s] (0.2 deg/s)
	// Accelerometer
	double accNoiseDensity = 2.0e-3;  ///< [m/s^2/sqrt(Hz)]
	double accBiasRw = 2.0e-4;        ///< bias random walk [m/s^3/sqrt(Hz)]
	double accBiasInit = 0.02;  ///< sigma of the initial bias per axis [m/s^2]
	// Magnetometer
	double magNoiseDensity = 5.0e-4;  ///< [gauss/sqrt(Hz)]
	double magBiasRw =
	    1.0e-5;  ///< bias (residual hard-iron) random walk [gauss/sqrt(s)]
	double magBiasInit =
	    3.0e-3;              ///< sigma of the initial bias per axis [gauss]
	double magField = 0.48;  ///< Earth field magnitude [gauss]
	double magDipDeg = 60;  ///< inclination, positive = field points down [deg]
	double magDeclinationDeg =
	    0;  ///< angle of the field east of {W}'s x axis [deg]
	// Local magnetic disturbance (e.g. a steel cabinet): inside a sphere the
	// field gets + field_W * (1 - (r/R)^2)^2.
	bool disturbance = false;                        ///< enable the disturbance
	Eigen::Vector3d disturbanceCenter{0, 1.5, 1.0};  ///< centre in {W} [m]
	double disturbanceRadius = 1.5;                  ///< radius [m]
	Eigen::Vector3d disturbanceField{0.0, 0.3,
	                                 0.2};  ///< peak added field in {W} [gauss]
	// Xsens-like orientation output (IMU_ORI_QUAT_*: R_WI as a quaternion)
	bool orientation = false;  ///< write IMU_ORI_QUAT_{X,Y,Z,W}
	double orientationNoiseDeg =
	    0.5;  ///< white noise per axis on the quaternion [deg]
	// [calibration]
	Eigen::Matrix3d R_IC;    ///< orientation of {C} in {I}: p_I = R_IC p_C
	double timeOffsetS = 0;  ///< IMU stamp = true time + offset [s]

	ImuParams();
	/** Sets R_IC from MRPT yaw, pitch, roll [deg] (R = Rz Ry Rx). */
	void setR_IC_ypr(double yawDeg, double pitchDeg, double rollDeg);
	/** Earth field in {W} [gauss] from magField, magDipDeg, magDeclinationDeg.
	 */
	Eigen::Vector3d earthField_W() const;
	/** Total field at a point of {W} (Earth + disturbance) [gauss]. */
	Eigen::Vector3d field_W(const Eigen::Vector3d& p_W) const;
	/** Reads [imuSection] (rates, noise, field, disturbance, label) and
	 * [calibSection] (R_IC_ypr_deg, time_offset_s); both optional. */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& imuSection = "imu",
	                        const std::string& calibSection = "calibration");
	/** All noises, biases and the orientation noise set to zero. */
	void makeNoiseless();
};

/** The true values behind one IMU sample. */
struct ImuTruth
{
	double tStamp = 0;  ///< timestamp written in the rawlog [s]
	double tTrue = 0;   ///< instant of the motion it measures [s]
	Eigen::Vector3d omega_I, f_I,
	    m_I;  ///< noiseless gyro [rad/s], specific force [m/s^2], field [gauss]
	Eigen::Vector3d gyroBias, accBias;  ///< biases added to this sample
	Eigen::Vector3d magBias =
	    Eigen::Vector3d::Zero();  ///< magnetometer bias [gauss]
	Eigen::Quaterniond q_WI;      ///< true orientation of {I} in {W}
};

/** Generates IMU samples along a motion, sample by sample, deterministic for
 * a seed (its own random stream). */
class ImuSimulator
{
 public:
	ImuSimulator(const ImuParams& p, uint64_t seed);
	/** Sample at IMU timestamp tStamp [s]; the motion is evaluated at
	 * tStamp - timeOffsetS on the model's axis shifted by \a modelT0 (model
	 * time = true time - modelT0). Biases advance by the time since the
	 * previous call. */
	mrpt::obs::CObservationIMU::Ptr sample(const MotionModel& motion,
	                                       double tStamp, double modelT0,
	                                       ImuTruth* truth = nullptr);

 private:
	ImuParams p_;
	uint64_t seed_;
	uint64_t n_ = 0;
	double lastT_ = 0;
	Eigen::Vector3d bg_, ba_, bm_;
};

/** IMU readings synthesised from a TUM ground-truth trajectory of poses T_WC
 * (e.g. a real RGB-D recording without IMU), for the IMU-aided pipeline.
 *
 * The trajectory is interpolated with SplineMotion (C2 cubic splines; noise in
 * the ground truth is NOT smoothed and appears amplified in the
 * accelerometer); samples are taken at params.rateHz from the first to the last
 * pose stamp, stamped on the trajectory's own clock (+ params.timeOffsetS),
 * with the noise model of ImuParams. Deterministic for (trajectory, params,
 * seed). The sensor label is params.label with "_SYNTH" appended unless it
 * already contains "SYNTH", so that such data is never mistaken for a real IMU.
 * \param truth if not null, receives the true values of each sample.
 * \throws std::invalid_argument for fewer than 4 poses or non-increasing
 * stamps. */
std::vector<mrpt::obs::CObservationIMU::Ptr> synthesizeImu(
    const Trajectory& trajectory, const ImuParams& params, uint64_t seed,
    std::vector<ImuTruth>* truth = nullptr);

/** R_IC and time_offset_s of a synthetic IMU from [calibration] of \a cfg
 * (no section: \a imu unchanged): either the egomotion module's key R_IC
 * (9 reals, row major, p_I = R_IC p_C; ConfigError if not a rotation) or
 * the simulator's R_IC_ypr_deg. Not strict about other keys: the section
 * belongs to those modules, whose readers are. */
void loadSynthCalibration(const mrpt::config::CConfigFileBase& cfg,
                          ImuParams& imu);

/** IMU readings synthesised from the ground truth \a gt (T_WC) of an
 * imported recording (bims-import-tum --synth-imu): the default IMU labelled
 * \a label (+ "_SYNTH"), R_IC and time_offset_s from \a calibration
 * (loadSynthCalibration; nullptr: the defaults), \a seed. */
std::vector<mrpt::obs::CObservation::Ptr> synthesizeImportImu(
    const Trajectory& gt, const std::string& label,
    const mrpt::config::CConfigFileBase* calibration, uint64_t seed);

/** Writes the true IMU values as a text table (imuTruthHeader(), then one
 * imuTruthLine() per sample). Throws std::runtime_error on I/O failure. */
void saveImuTruth(const std::string& path, const std::vector<ImuTruth>& truth);
/** The comment lines naming the columns of the IMU truth table. */
std::string imuTruthHeader();
/** One sample's line of the IMU truth table (newline included). */
std::string imuTruthLine(const ImuTruth& t);

}  // namespace bims::sim
