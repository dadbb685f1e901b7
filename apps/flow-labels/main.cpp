// bims-flow-labels: optical-flow consistency labels for one RGB-D image pair.
//
//   bims-flow-labels RGB0.png RGB1.png DEPTH1.png -o OUTDIR [--config EXP.ini]
//       [--depth-scale 5000] [--fx F --fy F --cx C --cy C] [--pose "x y z yaw
//       pitch roll"]
//
// Computes the observed flow of frame 1 towards frame 0, the flow expected from
// frame 1's depth and the relative pose T_{C0 C1} (identity by default: a still
// camera), and the Diff/notDiff labels; writes colour pictures and prints
// per-stage timings. Useful to tune [flow] on real sensor data.
#include <bims/apps/app.h>
#include <bims/apps/flow_labels_run.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-flow-labels",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "Optical-flow consistency labels (Diff/notDiff) for one RGB-D "
		        "pair",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> aRgb0(
		        "rgb0", "previous RGB image", true, "", "RGB0.png", cmd);
		    TCLAP::UnlabeledValueArg<std::string> aRgb1(
		        "rgb1", "current RGB image", true, "", "RGB1.png", cmd);
		    TCLAP::UnlabeledValueArg<std::string> aDepth1(
		        "depth1", "current depth (16-bit PNG)", true, "", "DEPTH1.png",
		        cmd);
		    TCLAP::ValueArg<std::string> aOut("o", "out", "output folder", true,
		                                      "", "OUTDIR", cmd);
		    TCLAP::ValueArg<std::string> aCfg(
		        "c", "config", "experiment .ini ([flow]; [input] image limits)",
		        false, "", "EXP.ini", cmd);
		    TCLAP::ValueArg<double> aScale("", "depth-scale",
		                                   "depth units per metre", false,
		                                   5000.0, "S", cmd);
		    TCLAP::ValueArg<double> aFx(
		        "", "fx", "focal x [px] (default 525 at 640 wide)", false, 0,
		        "F", cmd);
		    TCLAP::ValueArg<double> aFy("", "fy", "focal y [px]", false, 0, "F",
		                                cmd);
		    TCLAP::ValueArg<double> aCx("", "cx", "principal point x [px]",
		                                false, -1, "C", cmd);
		    TCLAP::ValueArg<double> aCy("", "cy", "principal point y [px]",
		                                false, -1, "C", cmd);
		    TCLAP::ValueArg<std::string> aPose(
		        "", "pose", "T_C0C1 as 'x y z yaw pitch roll' (m, deg)", false,
		        "0 0 0 0 0 0", "POSE", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    bims::inRange(aScale, 1e-6, 1e9);
		    // 0 (fx, fy) and -1 (cx, cy): from the image size when not given
		    if (aFx.isSet()) bims::inRange(aFx, 1e-3, 1e6);
		    if (aFy.isSet()) bims::inRange(aFy, 1e-3, 1e6);
		    if (aCx.isSet()) bims::inRange(aCx, -1e6, 1e6);
		    if (aCy.isSet()) bims::inRange(aCy, -1e6, 1e6);
		    return bims::apps::runFlowLabels(
		        {aRgb0.getValue(), aRgb1.getValue(), aDepth1.getValue(),
		         aOut.getValue(), bims::givenValue(aCfg), aScale.getValue(),
		         aFx.getValue(), aFy.getValue(), aCx.getValue(), aCy.getValue(),
		         aPose.getValue()});
	    });
}
