// bims-calib-depth CONFIG.ini IN.rawlog [--frames A:B] [--poses TRAJ.txt]
//                  -o OUT.ini
// Fits the depth sensor's smooth distortion (docs/ego.md, "Depth
// correction") to a stretch of a static scene: point-to-plane residuals
// between frame pairs at known poses (--poses, a TUM trajectory) or at the
// poses of bims' own frame-to-frame vision odometry (no ground truth
// needed). Writes a [depth_correction] section to paste into (or include
// with) the experiment .ini. The run: bims::apps::runDepthCalibration
// (calibration_run.h).
#include <bims/apps/app.h>
#include <bims/apps/calibration_run.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-calib-depth",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "Fits the depth sensor's smooth distortion to a static stretch "
		        "of a recording and writes a [depth_correction] section.",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> cfgArg(
		        "CONFIG", "experiment .ini ([camera], [sensors])", true, "",
		        "CONFIG.ini", cmd);
		    TCLAP::UnlabeledValueArg<std::string> inArg(
		        "RAWLOG", "input rawlog (RGB-D)", true, "", "IN.rawlog", cmd);
		    TCLAP::ValueArg<std::string> framesArg(
		        "", "frames",
		        "3D-scan indices A:B (inclusive) of a stretch without moving "
		        "objects (default: all)",
		        false, "", "A:B", cmd);
		    TCLAP::ValueArg<std::string> posesArg(
		        "", "poses",
		        "TUM trajectory of the camera (e.g. ground truth); default: "
		        "bims' frame-to-frame vision odometry",
		        false, "", "TRAJ.txt", cmd);
		    TCLAP::ValueArg<std::string> outArg(
		        "o", "out", "where to write the [depth_correction] section",
		        true, "", "OUT.ini", cmd);
		    TCLAP::ValueArg<double> maxArg(
		        "", "max-correction",
		        "refuse a fit that corrects any pixel by more than this "
		        "fraction (0.1): the poses did not fit a static scene",
		        false, 0.1, "FRACTION", cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    return bims::apps::runDepthCalibration(
		        {cfgArg.getValue(), inArg.getValue(), framesArg.getValue(),
		         posesArg.getValue(), outArg.getValue(),
		         bims::inRange(maxArg, 1e-6, 1.0, "a fraction of the depth"),
		         !quiet.getValue()});
	    });
}
