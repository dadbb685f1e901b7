// bims-eval attitude (eval_run.h).
#include <bims/apps/app.h>
#include <bims/apps/eval_run.h>
#include <bims/apps/output_checks.h>
#include <bims/eval/attitude_metrics.h>
#include <bims/io/json.h>
#include <bims/io/trajectory.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace bims::apps
{
namespace ev = bims::eval;

int runEvalAttitude(const EvalAttitudeOptions& o)
{
	checkOutputsSpareInputs({o.ref, o.est},
	                        o.json ? std::vector<std::string>{*o.json}
	                               : std::vector<std::string>{});
	if (!(o.skip_s >= 0)) throw UsageError("--skip-s must be >= 0");
	if (!(o.maxDt > 0)) throw UsageError("--max-dt must be > 0");
	ev::AttitudeOptions a;
	try
	{
		a.upRef = ev::axisFromName(o.refUp);
		a.upEst = ev::axisFromName(o.estUp);
	}
	catch (const std::invalid_argument& e)
	{
		throw UsageError(std::string("--ref-up/--est-up: ") + e.what());
	}
	a.skip_s = o.skip_s;
	a.maxTimeDifference = o.maxDt;
	Trajectory traj[2];
	for (int k = 0; k < 2; k++)
	{
		const std::string& p = k ? o.est : o.ref;
		if (!std::filesystem::exists(p))
			throw std::runtime_error(p + ": file not found");
		traj[k] = loadTumTrajectory(p);
		if (traj[k].empty())
			throw std::runtime_error(p + ": trajectory is empty");
	}
	ev::AttitudeResult r;
	try
	{
		r = ev::computeAttitudeError(traj[0], traj[1], a);
	}
	catch (const std::invalid_argument& e)
	{
		throw std::runtime_error(o.ref + " vs " + o.est + ": " + e.what());
	}
	std::printf(
	    "associated %zu of %zu estimated poses with %zu reference poses "
	    "(max dt %.3f s, first %.2f s skipped), %.2f s\n",
	    r.pairs.size(), traj[1].size(), traj[0].size(), a.maxTimeDifference,
	    a.skip_s, r.span_s);
	std::printf("tilt_rmse %.3f deg (mean %.3f, median %.3f, max %.3f)\n",
	            r.tilt.rmse, r.tilt.mean, r.tilt.median, r.tilt.max);
	std::printf("heading_drift %.3f deg/min (max |heading error| %.3f deg)\n",
	            r.heading_drift_deg_min, r.heading_max_abs_deg);
	if (o.json)
	{
		Json j;
		j["reference"] = o.ref;
		j["estimate"] = o.est;
		j["pairs"] = r.pairs.size();
		j["span_s"] = jsonNumber(r.span_s, 3);
		j["skip_s"] = a.skip_s;
		j["tilt_rmse_deg"] = jsonNumber(r.tilt.rmse, 4);
		j["tilt_max_deg"] = jsonNumber(r.tilt.max, 4);
		j["heading_drift_deg_min"] = jsonNumber(r.heading_drift_deg_min, 4);
		j["heading_max_abs_deg"] = jsonNumber(r.heading_max_abs_deg, 4);
		writeJsonFile(*o.json, j);
	}
	return 0;
}

}  // namespace bims::apps
