// bims-eval traj (eval_run.h).
#include <bims/apps/app.h>
#include <bims/apps/eval_run.h>
#include <bims/apps/output_checks.h>
#include <bims/eval/plots.h>
#include <bims/eval/trajectory_metrics.h>
#include <bims/io/json.h>
#include <bims/io/trajectory.h>

#include <mrpt/core/format.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace bims::apps
{
namespace ev = bims::eval;

namespace
{
Trajectory load(const std::string& path)
{
	if (!std::filesystem::exists(path))
		throw std::runtime_error(path + ": file not found");
	auto t = loadTumTrajectory(path);
	if (t.empty()) throw std::runtime_error(path + ": trajectory is empty");
	return t;
}
/** The body-frame rule (eval::orientationsDisagreeWithPositions): the
 * warning names the likely cause and the fix. */
void warnIfOrientationsDisagree(const EvalTrajOptions& o,
                                const ev::TrajectoryReport& rep,
                                const Trajectory& gt, const Trajectory& est)
{
	const ev::ErrorStats disp =
	    ev::displacementErrors(gt, est, rep.rpe, rep.ate, rep.rpeOptions);
	if (!ev::orientationsDisagreeWithPositions(rep.rpe.trans, disp,
	                                           rep.ate.stats, o.delta))
		return;
	std::fprintf(
	    stderr,
	    "bims-eval traj: warning: the RPE (%.4f m/s, %.2f deg/s) is %.1fx what "
	    "the positions alone give for the same pairs (%.4f m/s) while the ATE "
	    "is %.4f m: the orientations of %s and %s are not of the same body. "
	    "Likely cause: the ground truth holds the poses of another body than "
	    "the camera, e.g. a Bonn RGB-D Dynamic folder's groundtruth.txt (the "
	    "motion-capture marker's). Fix: import the folder with "
	    "`bims-import-tum FOLDER -o OUT.rawlog -c bonn.ini` (or --bonn-gt) "
	    "and score against OUT_gt/groundtruth.txt, the camera's poses\n",
	    rep.rpe.trans.rmse, rep.rpe.rot.rmse,
	    disp.rmse > 0 ? rep.rpe.trans.rmse / disp.rmse : INFINITY, disp.rmse,
	    rep.ate.stats.rmse, o.gt.c_str(), o.est.c_str());
}

/** The frame-to-frame lines (docs/eval.md): the key, the value, details. */
void printJumps(const ev::JumpResult& j)
{
	std::printf(
	    "max_frame_trans_err %.4f m (at t %.6f, est pose %zu; median %.4f over "
	    "%zu frame pairs)\n",
	    j.stats.max, j.maxTime, j.maxEstIndex, j.stats.median,
	    j.transErrors.size());
	std::printf("frames_over_jump %zu (of %zu frame pairs, error > %.3f m)\n",
	            j.framesOverJump, j.transErrors.size(), j.jumpM);
	std::printf(
	    "max_speed %.4f m/s (at t %.6f, est pose %zu; reference %.4f m/s "
	    "there)\n",
	    j.maxSpeed, j.maxSpeedTime, j.maxSpeedEstIndex, j.refSpeedAtMax);
}

void checkEvalTrajOptions(const EvalTrajOptions& o)
{
	if (!(o.jumpM >= 0) || !std::isfinite(o.jumpM))
		throw UsageError("--jump-m must be >= 0");
	std::vector<std::string> outputs;
	for (const auto* out : {&o.plot, &o.json})
		if (*out) outputs.push_back(**out);
	checkOutputsSpareInputs({o.gt, o.est}, outputs);
}

/** The scores of \a est against \a gt (ATE, RPE, jumps); \a rpeError:
 * why the RPE is not available ("" when it is). */
ev::TrajectoryReport scoreTrajectory(const EvalTrajOptions& o,
                                     const Trajectory& gt,
                                     const Trajectory& est,
                                     std::string& rpeError)
{
	ev::TrajectoryReport rep;
	rep.gtPath = o.gt;
	rep.estPath = o.est;
	rep.gtPoses = gt.size();
	rep.estPoses = est.size();
	rep.ateOptions.maxTimeDifference = o.maxDt;
	rep.ateOptions.timeOffset = o.offset;
	rep.rpeOptions.delta = o.delta;
	rep.rpeOptions.timeOffset = o.offset;
	const std::string both = rep.gtPath + " vs " + rep.estPath + ": ";
	try
	{
		rep.ate = ev::computeAte(gt, est, rep.ateOptions);
	}
	catch (const std::invalid_argument& e)
	{
		throw std::runtime_error(both + e.what());
	}
	try
	{
		rep.rpe = ev::computeRpe(gt, est, rep.rpeOptions);
	}
	catch (const std::invalid_argument& e)
	{
		rpeError = e.what();
	}
	rep.jumps = ev::computeJumps(gt, est, rep.ate.pairs, {o.jumpM});
	return rep;
}

/** The score lines on stdout (docs/eval.md). */
void printTrajectoryScores(const EvalTrajOptions& o,
                           const ev::TrajectoryReport& rep,
                           const Trajectory& gt, const Trajectory& est,
                           const std::string& rpeError)
{
	std::printf(
	    "associated %zu of %zu estimated poses with %zu ground-truth poses "
	    "(max dt %.3f s)\n",
	    rep.ate.pairs.size(), est.size(), gt.size(), o.maxDt);
	const auto& a = rep.ate.stats;
	std::printf("ate_rmse %.4f m (mean %.4f, median %.4f, max %.4f)\n", a.rmse,
	            a.mean, a.median, a.max);
	if (rpeError.empty())
	{
		std::printf(
		    "rpe_trans_rmse %.4f m/s (mean %.4f, median %.4f; %zu pairs, "
		    "delta %.3g s)\n",
		    rep.rpe.trans.rmse, rep.rpe.trans.mean, rep.rpe.trans.median,
		    rep.rpe.pairs.size(), o.delta);
		std::printf("rpe_rot_rmse %.4f deg/s (mean %.4f, median %.4f)\n",
		            rep.rpe.rot.rmse, rep.rpe.rot.mean, rep.rpe.rot.median);
		warnIfOrientationsDisagree(o, rep, gt, est);
	}
	else
		std::printf("rpe not available: %s\n", rpeError.c_str());
	printJumps(rep.jumps);
}

/** The plot of both trajectories (the estimate aligned): --plot, or
 * EST_traj.png beside the estimate. */
void writeTrajectoryPlot(const EvalTrajOptions& o,
                         const ev::TrajectoryReport& rep, const Trajectory& gt,
                         const Trajectory& est)
{
	std::string path = o.plot.value_or("");
	if (path.empty())
		path = std::filesystem::path(rep.estPath).replace_extension().string() +
		       "_traj.png";
	const std::string title =
	    mrpt::format("%s  ATE RMSE %.3f m (%zu poses)",
	                 std::filesystem::path(rep.estPath).filename().c_str(),
	                 rep.ate.stats.rmse, rep.ate.pairs.size());
	ev::writePng(path, ev::plotTrajectories(
	                       gt, ev::alignTrajectory(est, rep.ate.T_alignment),
	                       rep.ate.pairs, title));
	std::fprintf(stderr, "bims-eval traj: plot written to %s\n", path.c_str());
}
}  // namespace

int runEvalTraj(const EvalTrajOptions& o)
{
	checkEvalTrajOptions(o);
	const auto gt = load(o.gt);
	const auto est = load(o.est);
	std::string rpeError;
	const ev::TrajectoryReport rep = scoreTrajectory(o, gt, est, rpeError);
	printTrajectoryScores(o, rep, gt, est, rpeError);
	if (o.json) writeJsonFile(*o.json, rep.toJson());
	if (!o.noPlot) writeTrajectoryPlot(o, rep, gt, est);
	return 0;
}

}  // namespace bims::apps
