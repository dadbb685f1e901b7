// The one rule for IMU samples that no sensor gives: a field that is not
// finite, or beyond what any IMU measures, makes the whole sample unusable.
#pragma once

#include <mrpt/obs/CObservationIMU.h>

#include <cstddef>
#include <deque>
#include <string>

namespace bims
{
/** Why \a imu cannot be used: its first present field that is NaN,
 * infinite or beyond the physical range of the quantity (e.g. "IMU_WX =
 * 1e+300 (beyond +-100 rad/s)"); empty when every present field is sane.
 * Ranges, far above any IMU: acceleration 2000 m/s^2, angular rate 100
 * rad/s, Euler angles 100 rad, quaternion components 1.01, velocity 1e4
 * m/s, position and altitude 1e8 m, magnetic field 1e4, pressure 1e7 Pa,
 * temperature 1000 degC. */
[[nodiscard]] std::string imuSampleProblem(
    const mrpt::obs::CObservationIMU& imu);

/** The IMU samples a replay does not use (imuSampleProblem), for bims-run
 * and bims-odom alike: each is counted, and the frame whose interval held
 * one is flagged. */
class RejectedImuSamples
{
 public:
	/** imuSampleProblem(imu); when not empty, the sample at \a t [s] is
	 * counted and remembered (the caller warns of it, naming the input). */
	[[nodiscard]] std::string check(const mrpt::obs::CObservationIMU& imu,
	                                double t);
	/** Whether samples stamped at or before \a t were rejected since the
	 * last call (each sample answers once). */
	bool upTo(double t);
	size_t count() const { return n_; }

 private:
	std::deque<double> stamps_;
	size_t n_ = 0;
};

}  // namespace bims
