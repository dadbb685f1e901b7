#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>
#include <bims/common/json.h>
#include <bims/common/trajectory.h>
#include <bims/eval/attitude_metrics.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "commands.h"

namespace ev = bims::eval;

int cmdAttitude(int argc, char** argv)
{
	TCLAP::CmdLine cmd(
	    "Attitude error of an estimated TUM trajectory's rotations against a "
	    "reference: tilt (the angle between the up directions seen from the "
	    "camera) and heading drift (the twist about up after aligning the "
	    "worlds at the first pose, its least-squares slope in deg/min). "
	    "Translations are not used (bims-odom --attitude writes the IMU "
	    "attitude filter's R_WC alone).",
	    ' ', bims::version());
	TCLAP::UnlabeledValueArg<std::string> refArg(
	    "REF", "reference trajectory (TUM format)", true, "", "REF.txt", cmd);
	TCLAP::UnlabeledValueArg<std::string> estArg(
	    "EST", "estimated trajectory (TUM format)", true, "", "EST.txt", cmd);
	TCLAP::ValueArg<std::string> refUp(
	    "", "ref-up",
	    "up axis of the reference's world: x, y, z, -x, -y, -z (default z; "
	    "ARKit and Stray Scanner: y)",
	    false, "z", "AXIS", cmd);
	TCLAP::ValueArg<std::string> estUp(
	    "", "est-up", "up axis of the estimate's world (default z: bims)",
	    false, "z", "AXIS", cmd);
	TCLAP::ValueArg<double> skip(
	    "", "skip-s",
	    "leave out the estimate's first S seconds (a filter's convergence; "
	    "default 0)",
	    false, 0.0, "S", cmd);
	TCLAP::ValueArg<double> maxDt(
	    "", "max-dt", "max time difference to associate poses [s] (0.02)",
	    false, 0.02, "S", cmd);
	TCLAP::ValueArg<std::string> json(
	    "", "json", "also write the figures as JSON", false, "", "FILE", cmd);
	bims::parseCommandLine(cmd, argc, argv);
	bims::checkOutputsSpareInputs({refArg.getValue(), estArg.getValue()},
	                              bims::givenValues(json));
	if (!(skip.getValue() >= 0))
		throw bims::UsageError("--skip-s must be >= 0");
	if (!(maxDt.getValue() > 0)) throw bims::UsageError("--max-dt must be > 0");
	ev::AttitudeOptions o;
	try
	{
		o.upRef = ev::axisFromName(refUp.getValue());
		o.upEst = ev::axisFromName(estUp.getValue());
	}
	catch (const std::invalid_argument& e)
	{
		throw bims::UsageError(std::string("--ref-up/--est-up: ") + e.what());
	}
	o.skip_s = skip.getValue();
	o.maxTimeDifference = maxDt.getValue();
	bims::Trajectory traj[2];
	for (int k = 0; k < 2; k++)
	{
		const std::string& p = k ? estArg.getValue() : refArg.getValue();
		if (!std::filesystem::exists(p))
			throw std::runtime_error(p + ": file not found");
		traj[k] = bims::loadTumTrajectory(p);
		if (traj[k].empty())
			throw std::runtime_error(p + ": trajectory is empty");
	}
	ev::AttitudeResult r;
	try
	{
		r = ev::computeAttitudeError(traj[0], traj[1], o);
	}
	catch (const std::invalid_argument& e)
	{
		throw std::runtime_error(refArg.getValue() + " vs " +
		                         estArg.getValue() + ": " + e.what());
	}
	std::printf(
	    "associated %zu of %zu estimated poses with %zu reference poses "
	    "(max dt %.3f s, first %.2f s skipped), %.2f s\n",
	    r.pairs.size(), traj[1].size(), traj[0].size(), o.maxTimeDifference,
	    o.skip_s, r.span_s);
	std::printf("tilt_rmse %.3f deg (mean %.3f, median %.3f, max %.3f)\n",
	            r.tilt.rmse, r.tilt.mean, r.tilt.median, r.tilt.max);
	std::printf("heading_drift %.3f deg/min (max |heading error| %.3f deg)\n",
	            r.heading_drift_deg_min, r.heading_max_abs_deg);
	if (json.isSet())
	{
		bims::Json j;
		j["reference"] = refArg.getValue();
		j["estimate"] = estArg.getValue();
		j["pairs"] = r.pairs.size();
		j["span_s"] = bims::jsonNumber(r.span_s, 3);
		j["skip_s"] = o.skip_s;
		j["tilt_rmse_deg"] = bims::jsonNumber(r.tilt.rmse, 4);
		j["tilt_max_deg"] = bims::jsonNumber(r.tilt.max, 4);
		j["heading_drift_deg_min"] =
		    bims::jsonNumber(r.heading_drift_deg_min, 4);
		j["heading_max_abs_deg"] = bims::jsonNumber(r.heading_max_abs_deg, 4);
		bims::writeJsonFile(json.getValue(), j);
	}
	return 0;
}
