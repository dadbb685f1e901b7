#include <bims/common/imu_check.h>

#include <array>
#include <cmath>
#include <cstdio>

namespace bims
{
namespace
{
struct Field
{
	const char* name;
	double limit;  ///< largest absolute value of a real measurement
	const char* unit;
};
constexpr double kAcc = 2000, kRate = 100, kAngle = 100, kVel = 1e4, kPos = 1e8,
                 kMag = 1e4, kQuat = 1.01;
/** In the order of mrpt::obs::TIMUDataIndex. */
constexpr std::array<Field, mrpt::obs::COUNT_IMU_DATA_FIELDS> kFields = {{
    {"IMU_X_ACC", kAcc, "m/s^2"},
    {"IMU_Y_ACC", kAcc, "m/s^2"},
    {"IMU_Z_ACC", kAcc, "m/s^2"},
    {"IMU_WZ", kRate, "rad/s"},
    {"IMU_WY", kRate, "rad/s"},
    {"IMU_WX", kRate, "rad/s"},
    {"IMU_X_VEL", kVel, "m/s"},
    {"IMU_Y_VEL", kVel, "m/s"},
    {"IMU_Z_VEL", kVel, "m/s"},
    {"IMU_YAW", kAngle, "rad"},
    {"IMU_PITCH", kAngle, "rad"},
    {"IMU_ROLL", kAngle, "rad"},
    {"IMU_X", kPos, "m"},
    {"IMU_Y", kPos, "m"},
    {"IMU_Z", kPos, "m"},
    {"IMU_MAG_X", kMag, ""},
    {"IMU_MAG_Y", kMag, ""},
    {"IMU_MAG_Z", kMag, ""},
    {"IMU_PRESSURE", 1e7, "Pa"},
    {"IMU_ALTITUDE", kPos, "m"},
    {"IMU_TEMPERATURE", 1000, "degC"},
    {"IMU_ORI_QUAT_X", kQuat, ""},
    {"IMU_ORI_QUAT_Y", kQuat, ""},
    {"IMU_ORI_QUAT_Z", kQuat, ""},
    {"IMU_ORI_QUAT_W", kQuat, ""},
    {"IMU_YAW_VEL_GLOBAL", kRate, "rad/s"},
    {"IMU_PITCH_VEL_GLOBAL", kRate, "rad/s"},
    {"IMU_ROLL_VEL_GLOBAL", kRate, "rad/s"},
    {"IMU_X_ACC_GLOBAL", kAcc, "m/s^2"},
    {"IMU_Y_ACC_GLOBAL", kAcc, "m/s^2"},
    {"IMU_Z_ACC_GLOBAL", kAcc, "m/s^2"},
}};
static_assert(mrpt::obs::IMU_WX == 5 && mrpt::obs::IMU_MAG_X == 15 &&
                  mrpt::obs::IMU_ORI_QUAT_W == 24 &&
                  mrpt::obs::IMU_Z_ACC_GLOBAL == 30,
              "kFields follows mrpt::obs::TIMUDataIndex");
}  // namespace

std::string imuSampleProblem(const mrpt::obs::CObservationIMU& imu)
{
	for (size_t i = 0; i < kFields.size(); i++)
	{
		if (!imu.dataIsPresent[i]) continue;
		const double v = imu.rawMeasurements[i];
		const Field& f = kFields[i];
		if (std::isfinite(v) && std::abs(v) <= f.limit) continue;
		char buf[160];
		if (std::isfinite(v))
			std::snprintf(buf, sizeof(buf), "%s = %g (beyond +-%g%s%s)", f.name,
			              v, f.limit, *f.unit ? " " : "", f.unit);
		else
			std::snprintf(buf, sizeof(buf), "%s = %g (not finite)", f.name, v);
		return buf;
	}
	return {};
}

std::string RejectedImuSamples::check(const mrpt::obs::CObservationIMU& imu,
                                      double t)
{
	std::string bad = imuSampleProblem(imu);
	if (bad.empty()) return bad;
	++n_;
	stamps_.push_back(t);
	return bad;
}

bool RejectedImuSamples::upTo(double t)
{
	bool any = false;
	while (!stamps_.empty() && stamps_.front() <= t)
	{
		any = true;
		stamps_.pop_front();
	}
	return any;
}

}  // namespace bims
