// bims-eval attitude: its command line (the run: bims/apps/eval_run.h).
#include <bims/apps/app.h>
#include <bims/apps/eval_run.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include "commands.h"

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
	bims::apps::EvalAttitudeOptions o;
	o.ref = refArg.getValue();
	o.est = estArg.getValue();
	o.refUp = refUp.getValue();
	o.estUp = estUp.getValue();
	o.skip_s = skip.getValue();
	o.maxDt = maxDt.getValue();
	o.json = bims::givenValue(json);
	return bims::apps::runEvalAttitude(o);
}
