// bims-sweep's run (docs/sweep.md): a set of bims-run experiments, configs
// x [grid] overrides x rawlogs, run a few at a time or written as a jobs
// file, gathered into one table and a plot. The plan, the processes and the
// results are libs/sweep's (bims/sweep/plan.h, processes.h, results.h).
#pragma once

#include <bims/sweep/plan.h>

#include <atomic>
#include <string>

namespace bims::apps
{
struct SweepOptions
{
	std::string sweepFile;  ///< SWEEP.ini ("" with collect)
	std::string outDir;     ///< -o OUTDIR
	/** Runs at once; 0 = one per core. */
	int jobs = 1;
	std::string jobsFile;  ///< write the jobs there instead of running them
	/** Submit the runs as one Slurm array job (sbatch) instead of running
	 * them: the jobs file (default OUTDIR/jobs.txt), OUTDIR/slurm.sh (task
	 * i runs line i), the tasks' output in OUTDIR/slurm/. */
	bool slurm = false;
	/** More sbatch options, separated by spaces (e.g. "--partition=gpu
	 * --time=1:00:00"); only with slurm. */
	std::string sbatchArgs;
	bool dryRun = false;  ///< check and print the runs; write nothing
	bool quiet = false;   ///< no line per finished run
	/** Replace an earlier sweep's plan and results in outDir (its runs'
	 * outputs are replaced run by run: bims-run --overwrite). */
	bool overwrite = false;
	std::string plotMetric = "fps";
	/** Gather the results of OUTDIR (runs done elsewhere) instead. */
	std::string collect;
	/** SIGINT/SIGTERM (bims::installStopSignals): launch no more runs, pass
	 * the signal on to the running ones. */
	const std::atomic<bool>* stop = nullptr;
};

/** Scores a finished run against its ground truth ([truth] of SWEEP.ini)
 * with bims-eval's own runs: RUN/masks.json (bims-eval masks --json, no
 * overlays; the rawlog's depth with depth_valid), RUN/traj.json and
 * RUN/traj.png (bims-eval traj); what they print goes to RUN/eval.txt.
 * Only a run whose metrics.json says ok, and only the scores missing or
 * older than its metrics.json. Returns "" or what went wrong. */
std::string scoreRun(const sweep::SweepPlan& plan, const sweep::RunSpec& run,
                     const std::string& outDir);

/** The whole program; returns its exit code: 0 when every run is ok, 1
 * when one is not (a summary names them), 128 + the signal when stopped.
 * Throws UsageError for options that do not fit together, ConfigError
 * for a bad SWEEP.ini or config, before any run starts. */
int runSweep(const SweepOptions& opt);

}  // namespace bims::apps
