// IMU samples no sensor gives are named, field and value.
#include <bims/common/imu_check.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace mrpt::obs;

namespace
{
CObservationIMU sane()
{
	CObservationIMU o;
	o.set(IMU_X_ACC, 0.1);
	o.set(IMU_Y_ACC, -0.2);
	o.set(IMU_Z_ACC, 9.81);
	o.set(IMU_WX, 0.5);
	o.set(IMU_WY, -3.0);
	o.set(IMU_WZ, 30.0);  // a fast spin, still real
	o.set(IMU_ORI_QUAT_W, 1.0);
	o.set(IMU_ORI_QUAT_X, 0.0);
	o.set(IMU_ORI_QUAT_Y, 0.0);
	o.set(IMU_ORI_QUAT_Z, 0.0);
	o.set(IMU_TEMPERATURE, 25.0);
	return o;
}
}  // namespace

TEST(ImuCheck, ASaneSampleHasNoProblem)
{
	EXPECT_EQ(bims::imuSampleProblem(sane()), "");
	EXPECT_EQ(bims::imuSampleProblem(CObservationIMU()), "");  // no field
}

TEST(ImuCheck, NonFiniteAndAbsurdFieldsAreNamed)
{
	auto o = sane();
	o.set(IMU_WX, 1e300);
	EXPECT_EQ(bims::imuSampleProblem(o),
	          "IMU_WX = 1e+300 (beyond +-100 rad/s)");
	o = sane();
	o.set(IMU_Y_ACC, std::numeric_limits<double>::quiet_NaN());
	EXPECT_EQ(bims::imuSampleProblem(o), "IMU_Y_ACC = nan (not finite)");
	o = sane();
	o.set(IMU_ORI_QUAT_Z, -std::numeric_limits<double>::infinity());
	EXPECT_EQ(bims::imuSampleProblem(o), "IMU_ORI_QUAT_Z = -inf (not finite)");
	o = sane();
	o.set(IMU_MAG_X, 5e4);
	EXPECT_EQ(bims::imuSampleProblem(o), "IMU_MAG_X = 50000 (beyond +-10000)");
	// a field that is not present is not looked at
	o = sane();
	o.rawMeasurements[IMU_PRESSURE] = std::nan("");
	EXPECT_EQ(bims::imuSampleProblem(o), "");
}
