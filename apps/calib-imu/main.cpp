// bims-calib-imu CONFIG.ini IN.rawlog [--calib CALIB.ini] [-o OUT.ini]
// Estimates R_IC (camera {C} in IMU {I}, p_I = R_IC p_C) from a sequence:
// vision-only odometry gives each inter-frame rotation R_CprevC, the raw
// gyro integrated over the same interval gives R_IprevI, and R_IC solves
// Log(R_IprevI) = R_IC Log(R_CprevC) robustly (docs/ego.md). When the
// config already holds an R_IC, the angle between the two is reported.
// The run: bims::apps::runImuCalibration (calibration_run.h).
#include <bims/apps/app.h>
#include <bims/apps/calibration_run.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-calib-imu",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "Estimates the IMU-camera rotation R_IC from gyro vs visual "
		        "inter-frame rotations.",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> cfgArg(
		        "CONFIG", "experiment .ini", true, "", "CONFIG.ini", cmd);
		    TCLAP::UnlabeledValueArg<std::string> inArg(
		        "RAWLOG", "input rawlog (RGB-D + IMU)", true, "", "IN.rawlog",
		        cmd);
		    TCLAP::ValueArg<std::string> calibArg(
		        "", "calib",
		        "extra .ini with [calibration] [camera] [sensors] (its R_IC, "
		        "if any, is the reference the estimate is compared with)",
		        false, "", "CALIB.ini", cmd);
		    TCLAP::ValueArg<std::string> outArg(
		        "o", "out", "write the estimate as a [calibration] section",
		        false, "", "OUT.ini", cmd);
		    TCLAP::ValueArg<double> minAngle(
		        "", "min-angle-deg",
		        "skip frame pairs rotating less than this (0.3)", false, 0.3,
		        "DEG", cmd);
		    TCLAP::ValueArg<double> thr(
		        "", "inlier-deg",
		        "inlier limit on the rotation-vector residual (0.3)", false,
		        0.3, "DEG", cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv, {{"-c", "--calib"}});
		    return bims::apps::runImuCalibration(
		        {cfgArg.getValue(), inArg.getValue(), calibArg.getValue(),
		         bims::givenValue(outArg), minAngle.getValue(), thr.getValue(),
		         !quiet.getValue()});
	    });
}
