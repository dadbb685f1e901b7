// bims-maps-figure: the three grids over a rawlog with ground-truth poses,
// rendered as the paper's Fig. 4 (figure.h; docs/maps.md).
//
//   bims-maps-figure RAWLOG GT_DIR {OUT.png | -o OUT.png} [--max-frames N]
//                    [--voxel M]
#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include "figure.h"

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-maps-figure",
	    [&]
	    {
		    TCLAP::CmdLine cmd(
		        "Runs the three grids over a rawlog with ground-truth poses "
		        "and "
		        "masks (bims-sim's OUT_gt/) and renders the paper's Fig. 4 "
		        "colouring to a PNG.",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> aIn(
		        "rawlog", "Input rawlog", true, "", "IN.rawlog", cmd);
		    TCLAP::UnlabeledValueArg<std::string> aGt(
		        "gt", "Ground-truth folder (groundtruth.txt, masks/)", true, "",
		        "GT_DIR", cmd);
		    TCLAP::ValueArg<std::string> aOutOpt(
		        "o", "out", "Output PNG (or as the third word)", false, "",
		        "OUT.png", cmd);
		    TCLAP::UnlabeledValueArg<std::string> aOut(
		        "out_png", "Output PNG (or -o)", false, "", "OUT.png", cmd);
		    TCLAP::ValueArg<int> aFrames("", "max-frames",
		                                 "Frames to integrate (default 60)",
		                                 false, 60, "N", cmd);
		    TCLAP::ValueArg<double> aVoxel("", "voxel",
		                                   "Voxel size [m] (default 0.05)",
		                                   false, 0.05, "M", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    if (aOut.isSet() == aOutOpt.isSet())
			    throw bims::UsageError(
			        "give the output PNG once: -o OUT.png or as the third "
			        "word");
		    const std::string out =
		        aOutOpt.isSet() ? aOutOpt.getValue() : aOut.getValue();
		    const int frames = bims::inRange(aFrames, 1, 100000000);
		    const double voxel = aVoxel.getValue();
		    if (frames < 1) throw bims::UsageError("--max-frames must be >= 1");
		    if (!(voxel > 0)) throw bims::UsageError("--voxel must be > 0");
		    bims::checkOutputsSpareInputs({aIn.getValue(), aGt.getValue()},
		                                  {out});
		    return renderGridsFigure(
		        {aIn.getValue(), aGt.getValue(), out, frames, voxel});
	    });
}
