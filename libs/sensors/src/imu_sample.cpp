#include <bims/sensors/imu_sample.h>

#include <mrpt/core/Clock.h>

#include <cmath>

using mrpt::obs::CObservationIMU;
using namespace mrpt::obs;  // the IMU_* data indices

namespace bims::sensors
{
ImuSample imuSampleFrom(const CObservationIMU& o)
{
	ImuSample s;
	s.t = mrpt::Clock::toDouble(o.timestamp);
	if (o.has(IMU_WX) && o.has(IMU_WY) && o.has(IMU_WZ))
	{
		s.hasGyro = true;
		s.gyro = {o.get(IMU_WX), o.get(IMU_WY), o.get(IMU_WZ)};
	}
	if (o.has(IMU_X_ACC) && o.has(IMU_Y_ACC) && o.has(IMU_Z_ACC))
	{
		s.hasAcc = true;
		s.acc = {o.get(IMU_X_ACC), o.get(IMU_Y_ACC), o.get(IMU_Z_ACC)};
	}
	if (o.has(IMU_MAG_X) && o.has(IMU_MAG_Y) && o.has(IMU_MAG_Z))
	{
		s.hasMag = true;
		s.mag = {o.get(IMU_MAG_X), o.get(IMU_MAG_Y), o.get(IMU_MAG_Z)};
	}
	if (o.has(IMU_ORI_QUAT_W) && o.has(IMU_ORI_QUAT_X) &&
	    o.has(IMU_ORI_QUAT_Y) && o.has(IMU_ORI_QUAT_Z))
	{
		Eigen::Quaterniond q(o.get(IMU_ORI_QUAT_W), o.get(IMU_ORI_QUAT_X),
		                     o.get(IMU_ORI_QUAT_Y), o.get(IMU_ORI_QUAT_Z));
		if (std::abs(q.norm() - 1) < 1e-2) s.q_WI = q.normalized();
	}
	const auto finite = [](const Eigen::Vector3d& v) { return v.allFinite(); };
	if (!finite(s.gyro)) s.hasGyro = false;
	if (!finite(s.acc)) s.hasAcc = false;
	if (!finite(s.mag)) s.hasMag = false;
	return s;
}

}  // namespace bims::sensors
