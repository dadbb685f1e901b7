// bims-flow-check: where do the flow labels' false positives come from?
//
//   bims-flow-check CONFIG.ini IN.rawlog --gt GT.txt [--frames A:B]
//                   [--csv FRAMES.csv] [--strip OUT.png --strip-frames i,j,..]
//                   [-q]
//
// Runs the pipeline (flow-only variant) and, for every frame, labels the
// observed flow against the expected flow of several relative poses:
//   ego   the egomotion stage's T_CprevC (features; IMU rotation in imu mode)
//   used  the pose the pipeline used (ego, or its dense-flow refinement)
//   gt    the ground truth's relative pose (interpolated at the frame stamps)
//   flow  the SE(3) fitted to the dense observed flow from ego (the pose that
//         best explains the images' static majority; flow_pose.h)
// and prints, per pose, the Diff fraction of the valid-depth pixels and the
// median |observed - expected| flow, plus the rotation / translation of each
// pose against gt and flow. A summary (mean over frames) ends the output.
// --strip writes a picture: for each listed frame the RGB image with the
// used pose's Diff pixels in red (docs/journal/pipeline.md). The logic:
// bims/apps/flow_check.h, bims/flow/pose_check.h.
#include <bims/apps/app.h>
#include <bims/apps/flow_check.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-flow-check",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "bims: flow-label false positives per relative pose source",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> aCfg(
		        "config", "experiment .ini", true, "", "CONFIG.ini", cmd);
		    TCLAP::UnlabeledValueArg<std::string> aIn(
		        "rawlog", "input rawlog", true, "", "IN.rawlog", cmd);
		    TCLAP::ValueArg<std::string> aGt(
		        "", "gt", "ground-truth TUM trajectory (T_WC)", true, "",
		        "GT.txt", cmd);
		    TCLAP::ValueArg<std::string> aFrames(
		        "", "frames", "3D-scan indices A:B", false, "", "A:B", cmd);
		    TCLAP::ValueArg<std::string> aCsv("", "csv", "per-frame CSV", false,
		                                      "", "FRAMES.csv", cmd);
		    TCLAP::ValueArg<std::string> aStrip(
		        "", "strip", "PNG strip of Diff masks over RGB", false, "",
		        "OUT.png", cmd);
		    TCLAP::ValueArg<std::string> aStripFrames(
		        "", "strip-frames", "comma-separated scan indices for --strip",
		        false, "", "i,j,...", cmd);
		    TCLAP::ValueArg<std::string> aVariant(
		        "", "variant", "pipeline variant (default flow-only)", false,
		        "flow-only", "VARIANT", cmd);
		    TCLAP::SwitchArg aQuiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    using bims::givenValue;
		    return bims::apps::runFlowCheck(
		        {aCfg.getValue(), aIn.getValue(), aGt.getValue(),
		         aFrames.getValue(), givenValue(aCsv), givenValue(aStrip),
		         aStripFrames.getValue(), aVariant.getValue(),
		         !aQuiet.getValue()});
	    });
}
