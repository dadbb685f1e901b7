// bims-sweep: a set of bims-run experiments, configs x [grid] overrides x
// rawlogs, into one table and a plot (docs/sweep.md).
//
//   bims-sweep SWEEP.ini -o OUTDIR [-j N] [--jobs-file FILE] [--dry-run] [-q]
//              [--plot-metric NAME] [--slurm [--sbatch "ARGS"]]
//   bims-sweep --collect OUTDIR [--plot-metric NAME]
#include <bims/apps/app.h>
#include <bims/apps/sweep_run.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-sweep",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "bims: run a sweep of bims-run experiments (docs/sweep.md)",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> aSweep(
		        "sweep", "sweep description (an example: docs/sweep.md)", false,
		        "", "SWEEP.ini", cmd);
		    TCLAP::ValueArg<std::string> aOut(
		        "o", "out", "output folder (runs/, results.*)", false, "",
		        "OUTDIR", cmd);
		    TCLAP::ValueArg<int> aJobs("j", "jobs",
		                               "runs at once (0: one per core)", false,
		                               1, "N", cmd);
		    TCLAP::ValueArg<std::string> aJobsFile(
		        "", "jobs-file",
		        "write one shell line per run there (and the run folders) "
		        "instead of running",
		        false, "", "FILE", cmd);
		    TCLAP::SwitchArg aSlurm(
		        "", "slurm",
		        "submit the runs as one Slurm array job (sbatch) instead of "
		        "running them; then --collect OUTDIR",
		        cmd);
		    TCLAP::ValueArg<std::string> aSbatch(
		        "", "sbatch",
		        "more sbatch options for --slurm, separated by spaces", false,
		        "", "ARGS", cmd);
		    TCLAP::SwitchArg aDry(
		        "", "dry-run", "check and list the runs, write nothing", cmd);
		    TCLAP::SwitchArg aOverwrite(
		        "", "overwrite",
		        "replace an earlier sweep's plan and results in OUTDIR (and "
		        "its runs' outputs, run by run)",
		        cmd);
		    TCLAP::SwitchArg aQuiet("q", "quiet", "no line per finished run",
		                            cmd);
		    TCLAP::ValueArg<std::string> aMetric(
		        "", "plot-metric",
		        "metric of results.png (a results.csv column)", false, "fps",
		        "NAME", cmd);
		    TCLAP::ValueArg<std::string> aCollect(
		        "", "collect",
		        "gather the results of OUTDIR's runs, done elsewhere", false,
		        "", "OUTDIR", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    bims::apps::SweepOptions o;
		    o.sweepFile = aSweep.getValue();
		    o.outDir = aOut.getValue();
		    o.jobs = aJobs.getValue();
		    o.jobsFile = aJobsFile.getValue();
		    o.dryRun = aDry.getValue();
		    o.slurm = aSlurm.getValue();
		    o.sbatchArgs = aSbatch.getValue();
		    o.quiet = aQuiet.getValue();
		    o.overwrite = aOverwrite.getValue();
		    o.plotMetric = aMetric.getValue();
		    o.collect = aCollect.getValue();
		    o.stop = &bims::installStopSignals();
		    return bims::apps::runSweep(o);
	    });
}
