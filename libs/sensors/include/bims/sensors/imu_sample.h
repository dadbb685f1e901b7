// One IMU reading as every module reads it from MRPT's CObservationIMU: the
// attitude filter, the frame source's IMU checks, the calibrations.
#pragma once

#include <mrpt/obs/CObservationIMU.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <optional>

namespace bims::sensors
{
/** One IMU reading, in the IMU body frame {I}. */
struct ImuSample
{
	double t = 0;  ///< IMU clock [s]
	bool hasGyro = false, hasAcc = false, hasMag = false;
	Eigen::Vector3d gyro = Eigen::Vector3d::Zero();  ///< omega_I [rad/s]
	Eigen::Vector3d acc = Eigen::Vector3d::Zero();   ///< specific force [m/s^2]
	Eigen::Vector3d mag = Eigen::Vector3d::Zero();   ///< field (sensor units)
	/** The sensor's own orientation R_WI ({W} = NWU), if it gives one. */
	std::optional<Eigen::Quaterniond> q_WI;
};

/** Converts an MRPT IMU observation (IMU_WX.., IMU_X_ACC.., IMU_MAG_X..,
 * IMU_ORI_QUAT_*); t = timestamp in seconds (mrpt::Clock::toDouble). */
ImuSample imuSampleFrom(const mrpt::obs::CObservationIMU& obs);

}  // namespace bims::sensors
