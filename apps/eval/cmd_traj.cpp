#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>
#include <bims/common/json.h>
#include <bims/common/trajectory.h>
#include <bims/eval/plots.h>
#include <bims/eval/trajectory_metrics.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "commands.h"

namespace ev = bims::eval;

namespace
{
bims::Trajectory load(const std::string& path)
{
	if (!std::filesystem::exists(path))
		throw std::runtime_error(path + ": file not found");
	auto t = bims::loadTumTrajectory(path);
	if (t.empty()) throw std::runtime_error(path + ": trajectory is empty");
	return t;
}
}  // namespace

int cmdTraj(int argc, char** argv)
{
	TCLAP::CmdLine cmd(
	    "ATE RMSE (after SE(3) Horn alignment) and RPE (m/s, deg/s) of an "
	    "estimated TUM trajectory against ground truth, as the TUM RGB-D "
	    "benchmark tools; writes a PNG plot.",
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
	bims::parseCommandLine(cmd, argc, argv, {{"--plot", "--out"}});
	const std::vector<std::string> inputs = {gtArg.getValue(),
	                                         estArg.getValue()};
	bims::checkOutputsSpareInputs(inputs, bims::givenValues(plot, json));

	ev::TrajectoryReport rep;
	rep.gtPath = gtArg.getValue();
	rep.estPath = estArg.getValue();
	const auto gt = load(rep.gtPath);
	const auto est = load(rep.estPath);
	rep.gtPoses = gt.size();
	rep.estPoses = est.size();
	rep.ateOptions.maxTimeDifference = maxDt.getValue();
	rep.ateOptions.timeOffset = offset.getValue();
	rep.rpeOptions.delta = delta.getValue();
	rep.rpeOptions.timeOffset = offset.getValue();
	const std::string both = rep.gtPath + " vs " + rep.estPath + ": ";
	try
	{
		rep.ate = ev::computeAte(gt, est, rep.ateOptions);
	}
	catch (const std::invalid_argument& e)
	{
		throw std::runtime_error(both + e.what());
	}
	std::string rpeError;
	try
	{
		rep.rpe = ev::computeRpe(gt, est, rep.rpeOptions);
	}
	catch (const std::invalid_argument& e)
	{
		rpeError = e.what();
	}

	std::printf(
	    "associated %zu of %zu estimated poses with %zu ground-truth poses "
	    "(max dt %.3f s)\n",
	    rep.ate.pairs.size(), est.size(), gt.size(), maxDt.getValue());
	const auto& a = rep.ate.stats;
	std::printf("ate_rmse %.4f m (mean %.4f, median %.4f, max %.4f)\n", a.rmse,
	            a.mean, a.median, a.max);
	if (rpeError.empty())
	{
		std::printf(
		    "rpe_trans_rmse %.4f m/s (mean %.4f, median %.4f; %zu pairs, "
		    "delta %.3g s)\n",
		    rep.rpe.trans.rmse, rep.rpe.trans.mean, rep.rpe.trans.median,
		    rep.rpe.pairs.size(), delta.getValue());
		std::printf("rpe_rot_rmse %.4f deg/s (mean %.4f, median %.4f)\n",
		            rep.rpe.rot.rmse, rep.rpe.rot.mean, rep.rpe.rot.median);
	}
	else
		std::printf("rpe not available: %s\n", rpeError.c_str());

	if (json.isSet())
	{
		bims::writeJsonFile(json.getValue(), rep.toJson());
	}
	if (!noPlot.getValue())
	{
		std::string path = plot.getValue();
		if (path.empty())
			path = std::filesystem::path(rep.estPath)
			           .replace_extension()
			           .string() +
			       "_traj.png";
		char title[256];
		std::snprintf(title, sizeof(title), "%s  ATE RMSE %.3f m (%zu poses)",
		              std::filesystem::path(rep.estPath).filename().c_str(),
		              a.rmse, rep.ate.pairs.size());
		ev::writePng(path,
		             ev::plotTrajectories(
		                 gt, ev::alignTrajectory(est, rep.ate.T_alignment),
		                 rep.ate.pairs, title));
		std::fprintf(stderr, "bims-eval traj: plot written to %s\n",
		             path.c_str());
	}
	return 0;
}
