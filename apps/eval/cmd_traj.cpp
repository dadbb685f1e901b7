// bims-eval traj: its command line (the run: bims/apps/eval_run.h).
#include <bims/apps/app.h>
#include <bims/apps/eval_run.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include "commands.h"

int cmdTraj(int argc, char** argv)
{
	TCLAP::CmdLine cmd(
	    "ATE RMSE (after SE(3) Horn alignment) and RPE (m/s, deg/s) of an "
	    "estimated TUM trajectory against ground truth, as the TUM RGB-D "
	    "benchmark tools, and the frame-to-frame figures (the largest "
	    "translation difference from GT's, the frames over --jump-m, the "
	    "largest speed); writes a PNG plot.",
	    ' ', bims::version());
	TCLAP::UnlabeledValueArg<std::string> gtArg(
	    "GT", "ground-truth trajectory (TUM format)", true, "", "GT.txt", cmd);
	TCLAP::UnlabeledValueArg<std::string> estArg(
	    "EST", "estimated trajectory (TUM format)", true, "", "EST.txt", cmd);
	TCLAP::ValueArg<std::string> plot(
	    "o", "out", "PNG plot (default: EST without extension + _traj.png)",
	    false, "", "FILE.png", cmd);
	TCLAP::SwitchArg noPlot("", "no-plot", "do not write the plot", cmd);
	TCLAP::ValueArg<std::string> json(
	    "", "json", "also write the figures as JSON", false, "", "FILE", cmd);
	TCLAP::ValueArg<double> maxDt(
	    "", "max-dt", "max time difference to associate poses [s] (0.02)",
	    false, 0.02, "S", cmd);
	TCLAP::ValueArg<double> delta("", "delta", "RPE interval [s] (1)", false,
	                              1.0, "S", cmd);
	TCLAP::ValueArg<double> offset("", "offset",
	                               "time offset added to EST stamps [s] (0)",
	                               false, 0.0, "S", cmd);
	TCLAP::ValueArg<double> jumpM(
	    "", "jump-m",
	    "count the frames whose translation differs from GT's by more [m] "
	    "(0.03)",
	    false, 0.03, "M", cmd);
	bims::parseCommandLine(cmd, argc, argv, {{"--plot", "--out"}});
	bims::apps::EvalTrajOptions o;
	o.gt = gtArg.getValue();
	o.est = estArg.getValue();
	o.plot = bims::givenValue(plot);
	o.noPlot = noPlot.getValue();
	o.json = bims::givenValue(json);
	o.maxDt = maxDt.getValue();
	o.delta = delta.getValue();
	o.offset = offset.getValue();
	o.jumpM = jumpM.getValue();
	return bims::apps::runEvalTraj(o);
}
