// AttitudeFilter: the IMU orientation R_WI ({I} in the world {W}: z up,
// x magnetic north) from gyro, accelerometer and magnetometer.
//
// A nonlinear complementary filter on SO(3) (Mahony et al., IEEE TAC 2008)
// with gyro-bias estimation: the gyro is integrated between samples and the
// gravity direction (accelerometer) and the horizontal magnetic north
// (magnetometer, yaw only) pull the estimate back. Each aiding sensor is gated
// when it cannot be trusted: the accelerometer when | |f| - g | is large
// (linear acceleration), the magnetometer when its norm or dip departs from
// the reference field (magnetic disturbance). Derivation, gains and gating
// rules: docs/attitude.md. The filter keeps a short history so the attitude
// can be interpolated (slerp) at camera timestamps.
#pragma once

#include <bims/ego/params.h>
#include <bims/sensors/imu_sample.h>

#include <mrpt/obs/CObservationIMU.h>

#include <Eigen/Geometry>

#include <deque>
#include <optional>

namespace bims::ego
{
using sensors::ImuSample;
using sensors::imuSampleFrom;

class AttitudeFilter
{
 public:
	explicit AttitudeFilter(const AttitudeParams& p = {});

	/** Feeds one sample (must be later than the previous one: an older or
	 * equal timestamp is dropped and reported as kFlagOutOfOrder). Until the
	 * first sample with an accelerometer reading (and magnetometer, if
	 * used) arrives, the filter is not initialised and nothing is stored.
	 * \return kFlag* bits for this sample (gated sensors, gap, order). */
	uint32_t add(const ImuSample& s);

	/** Forces the state (e.g. a known or deliberately wrong start); the
	 * fast-convergence phase restarts at \a t. */
	void setState(const Eigen::Quaterniond& q_WI, double t);

	bool initialized() const { return initialized_; }
	/** true within init_time_s of the initialisation (fast-convergence
	 * phase: the absolute attitude is not trustworthy yet). */
	bool converging(double t) const
	{
		return !initialized_ || t - tInit_ < p_.init_time_s;
	}
	/** Latest estimate of R_WI. */
	Eigen::Quaterniond q_WI() const { return q_; }
	/** Estimated gyro bias [rad/s] in {I}. */
	Eigen::Vector3d gyroBias() const { return bias_; }
	/** Time of the latest sample [s]. */
	double lastTime() const { return tLast_; }

	/** R_WI at IMU time \a t [s]: slerp between the stored samples around
	 * t, or a short gyro extrapolation (<= max_gap_s) past the last one.
	 * nullopt (and kFlagImuMissing in *flags) when t is outside the
	 * history; kFlagImuGap when the samples around t are more than
	 * max_gap_s apart. */
	std::optional<Eigen::Quaterniond> attitudeAt(
	    double t, uint32_t* flags = nullptr) const;

	/** Same, on the gyro-only chain: the bias-corrected gyro integrated
	 * without any accelerometer/magnetometer correction (started from the
	 * filter's state). Its absolute value drifts, but the rotation between
	 * two nearby times, R_a^T R_b, is free of the corrections' noise: use it
	 * for inter-frame rotations. */
	std::optional<Eigen::Quaterniond> gyroAttitudeAt(
	    double t, uint32_t* flags = nullptr) const;

	/** Counters since construction. */
	struct Stats
	{
		size_t samples = 0, accelGated = 0, magGated = 0, gaps = 0,
		       outOfOrder = 0;
	};
	const Stats& stats() const { return stats_; }
	const AttitudeParams& params() const { return p_; }

 private:
	bool tryInitialize(const ImuSample& s);
	/** use_sensor_orientation: the sample's attitude as the estimate. */
	void takeSensorOrientation(const ImuSample& s);
	/** The accelerometer's tilt innovation added to \a e (false: gated or
	 * no accelerometer; kFlagAccelGated in \a flags when gated). */
	bool accelInnovation(const ImuSample& s, const Eigen::Vector3d& up_I,
	                     bool fast, Eigen::Vector3d& e, uint32_t& flags);
	/** The magnetometer's heading innovation added to \a e (false: gated,
	 * kFlagMagGated in \a flags). */
	bool magInnovation(const ImuSample& s, const Eigen::Matrix3d& R_WI,
	                   const Eigen::Vector3d& up_I, bool fast,
	                   Eigen::Vector3d& e, uint32_t& flags);
	/** The gyro rate plus kp times the innovation \a e over \a dt, the
	 * bias's integral, the gyro-only chain. */
	void integrate(const ImuSample& s, const Eigen::Matrix3d& R_WI,
	               const Eigen::Vector3d& e, bool corrected, bool fast,
	               double dt, uint32_t flags);
	bool magUsable(const Eigen::Vector3d& m, const Eigen::Vector3d& up_I);
	void push(double t);

	AttitudeParams p_;
	bool initialized_ = false;
	double tInit_ = 0, tLast_ = 0, tAccelOk_ = 0, tMagOk_ = 0;
	bool headingConverged_ = false;
	Eigen::Quaterniond q_ = Eigen::Quaterniond::Identity();
	Eigen::Vector3d bias_ = Eigen::Vector3d::Zero();
	Eigen::Vector3d lastGyro_ = Eigen::Vector3d::Zero();
	bool haveGyro_ = false;
	Eigen::Vector3d lastRate_ = Eigen::Vector3d::Zero();  // bias-corrected
	// Magnetic reference (learned or fixed).
	bool magRefReady_ = false;
	double magNormRef_ = 0, magDipRef_ = 0;  // sensor units, rad
	double magNormSum_ = 0, magDipSum_ = 0;
	int magRefCount_ = 0;
	struct Stamped
	{
		double t;
		Eigen::Quaterniond q, qg;  // filtered, gyro-only
	};

	std::optional<Eigen::Quaterniond> lookup(double t, uint32_t* flags,
	                                         bool gyroOnly) const;
	Eigen::Quaterniond qg_ = Eigen::Quaterniond::Identity();
	std::deque<Stamped> hist_;
	bool trimmed_ = false;  // hist_ lost its first samples (history_s)
	Stats stats_;
};

}  // namespace bims::ego
