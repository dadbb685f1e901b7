// bims-odom CONFIG.ini IN.rawlog -o TRAJ.txt [--calib CALIB.ini]
//           [--mode imu|vision] [--gyro-aid true|false] [--csv FRAMES.csv]
//           [--masks DIR] [--attitude ATT.txt]
// Egomotion alone: writes the camera trajectory T_WC in the TUM format and a
// per-stage timing summary. Works with or without IMU data in the rawlog
// (mode = vision for data without IMU).
#include <bims/apps/app.h>
#include <bims/apps/odometry_run.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-odom",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "Egomotion (IMU attitude + gyro-aided KLT + robust "
		        "translation) "
		        "of an RGB-D(+IMU) rawlog; TUM trajectory output.",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> cfgArg(
		        "CONFIG", "experiment .ini", true, "", "CONFIG.ini", cmd);
		    TCLAP::UnlabeledValueArg<std::string> inArg(
		        "RAWLOG", "input rawlog", true, "", "IN.rawlog", cmd);
		    TCLAP::ValueArg<std::string> outArg(
		        "o", "out", "output TUM trajectory", true, "", "TRAJ.txt", cmd);
		    TCLAP::ValueArg<std::string> calibArg(
		        "", "calib",
		        "extra .ini whose [calibration] [camera] [sensors] override "
		        "the "
		        "config (e.g. bims-sim's OUT_gt/calibration.ini)",
		        false, "", "CALIB.ini", cmd);
		    TCLAP::ValueArg<std::string> modeArg(
		        "", "mode", "override [odometry] mode: imu | vision", false, "",
		        "MODE", cmd);
		    TCLAP::ValueArg<std::string> aidArg(
		        "", "gyro-aid", "override [odometry] gyro_aid: true | false",
		        false, "", "BOOL", cmd);
		    TCLAP::ValueArg<std::string> csvArg(
		        "", "csv", "per-frame details (flags, inliers, stage times)",
		        false, "", "FRAMES.csv", cmd);
		    TCLAP::ValueArg<std::string> masksArg(
		        "", "masks",
		        "folder of moving masks NNNNNN.png (bims-run's OUT/masks, or "
		        "a simulation's ground truth): scan k-1's mask is left out of "
		        "frame k's tracking, as bims-run feeds its segmentation back "
		        "(without it: no mask, moving content is left to the robust "
		        "alignment)",
		        false, "", "DIR", cmd);
		    TCLAP::ValueArg<std::string> gtArg(
		        "", "gt",
		        "ground-truth TUM trajectory: adds to --csv the true angular "
		        "rate and the number of features tracked within 2 px of the "
		        "truth",
		        false, "", "GT.txt", cmd);
		    TCLAP::ValueArg<std::string> attArg(
		        "", "attitude",
		        "also write the IMU attitude filter's rotation R_WC = R_WI "
		        "R_IC at each frame (TUM, translation 0; compare with "
		        "bims-eval attitude)",
		        false, "", "ATT.txt", cmd);
		    TCLAP::ValueArg<std::string> gravArg(
		        "", "gravity-attitude",
		        "also write the odometry's R_WC levelled by the inertial "
		        "filter's gravity ([inertial]: the accelerometer's bias "
		        "estimated) at each frame (TUM, translation 0; compare with "
		        "bims-eval attitude)",
		        false, "", "ATT.txt", cmd);
		    TCLAP::ValueArg<long> maxArg(
		        "", "max-frames", "stop after N frames", false, 0, "N", cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv, {{"-c", "--calib"}});
		    using bims::givenValue;
		    return bims::apps::runOdometry(
		        {cfgArg.getValue(), inArg.getValue(), outArg.getValue(),
		         calibArg.getValue(), givenValue(modeArg), givenValue(aidArg),
		         givenValue(csvArg), givenValue(masksArg), givenValue(gtArg),
		         static_cast<size_t>(
		             bims::inRange(maxArg, 0L, 100000000L, "0 = all")),
		         !quiet.getValue(), givenValue(attArg), givenValue(gravArg)});
	    });
}
