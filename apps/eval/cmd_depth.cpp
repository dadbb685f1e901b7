// bims-eval depth-consistency: its command line (the run:
// bims/apps/eval_run.h).
#include <bims/apps/app.h>
#include <bims/apps/eval_run.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include "commands.h"

int cmdDepthConsistency(int argc, char** argv)
{
	TCLAP::CmdLine cmd(
	    "Checks poses with depth: the depth of scan k, back-projected with "
	    "T_WC(k) and re-projected into scan k+gap with T_WC(k+gap), is "
	    "compared "
	    "with that scan's depth. Prints the median |dz| over all pairs, and "
	    "the same assuming no motion as a baseline.",
	    ' ', bims::version());
	TCLAP::UnlabeledValueArg<std::string> rawlog(
	    "RAWLOG", "rawlog with 3D scans", true, "", "IN.rawlog", cmd);
	TCLAP::UnlabeledValueArg<std::string> gtArg(
	    "GT", "poses T_WC (TUM format), interpolated at the scans' stamps",
	    true, "", "GT.txt", cmd);
	TCLAP::ValueArg<int> gap("", "gap", "frames between compared scans (15)",
	                         false, 15, "N", cmd);
	TCLAP::ValueArg<int> step("", "step", "pixel subsampling (4)", false, 4,
	                          "S", cmd);
	TCLAP::ValueArg<int> maxFrames("", "max-frames",
	                               "use only the first N scans (0 = all)",
	                               false, 0, "N", cmd);
	bims::parseCommandLine(cmd, argc, argv);
	bims::inRange(maxFrames, 0, 100000000, "0 = all");
	bims::apps::DepthConsistencyOptions o;
	o.rawlog = rawlog.getValue();
	o.gt = gtArg.getValue();
	o.gap = gap.getValue();
	o.step = step.getValue();
	o.maxFrames = maxFrames.getValue();
	return bims::apps::runDepthConsistency(o);
}
