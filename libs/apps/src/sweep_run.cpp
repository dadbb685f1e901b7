#include <bims/apps/app.h>
#include <bims/apps/eval_run.h>
#include <bims/apps/output_checks.h>
#include <bims/apps/progress_bar.h>
#include <bims/apps/sweep_run.h>

#include <bims/common/share.h>
#include <bims/io/output_paths.h>
#include <bims/pipeline/run.h>
#include <bims/sweep/plan.h>
#include <bims/sweep/processes.h>
#include <bims/sweep/results.h>
#include <fcntl.h>
#include <mrpt/core/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <thread>

namespace bims::apps
{
using sweep::collectRun;
using sweep::Job;
using sweep::JobOutcome;
using sweep::PoolOptions;
using sweep::ResultTable;
using sweep::runCommand;
using sweep::runDir;
using sweep::runJobs;
using sweep::RunResult;
using sweep::shellLine;
using sweep::SweepPlan;
using sweep::SweepSpec;
using sweep::writeJobsFile;
using sweep::writePlan;
using sweep::writeResults;
namespace fs = std::filesystem;
namespace
{
/** stdout and stderr into a file while it lives (what bims-eval's runs
 * print when a sweep scores its runs). */
class OutputInto
{
 public:
	explicit OutputInto(const std::string& path)
	{
		std::fflush(stdout);
		std::fflush(stderr);
		const int fd = ::open(path.c_str(),
		                      O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
		if (fd < 0) throw std::runtime_error(path + ": cannot create");
		out_ = ::dup(1);
		err_ = ::dup(2);
		::dup2(fd, 1);
		::dup2(fd, 2);
		::close(fd);
	}
	~OutputInto()
	{
		std::fflush(stdout);
		std::fflush(stderr);
		::dup2(out_, 1);
		::dup2(err_, 2);
		::close(out_);
		::close(err_);
	}
	OutputInto(const OutputInto&) = delete;
	OutputInto& operator=(const OutputInto&) = delete;

 private:
	int out_ = -1, err_ = -1;
};

/** Whether \a score exists and is not older than \a source. */
bool upToDate(const std::string& score, const std::string& source)
{
	std::error_code e1, e2;
	const auto a = fs::last_write_time(score, e1);
	const auto b = fs::last_write_time(source, e2);
	return !e1 && !e2 && a >= b;
}

/** Scores each run (scoreRun) and collects it; a scoring failure makes
 * the run's status "not scored". */
sweep::RunResult scoreAndCollect(const SweepPlan& plan, size_t i,
                                 const std::string& outDir,
                                 const JobOutcome* outcome)
{
	const std::string error = scoreRun(plan, plan.runs[i], outDir);
	RunResult r = collectRun(plan.runs[i], outDir, outcome);
	if (!error.empty() && r.ok())
	{
		r.status = "not scored";
		r.error = error;
	}
	return r;
}

/** Writes the results and prints the summary; the exit code. */
int report(const ResultTable& t, const std::string& outDir,
           const std::string& plotMetric)
{
	writeResults(t, outDir, plotMetric);
	std::printf(
	    "bims-sweep: %zu runs, %zu ok; results in %s/results.csv, "
	    "results.md, results.png\n",
	    t.rows.size(), t.rows.size() - t.failures(), outDir.c_str());
	if (!t.failures()) return 0;
	std::fprintf(stderr, "bims-sweep: %zu of %zu runs not ok:\n", t.failures(),
	             t.rows.size());
	for (const auto& r : t.rows)
		if (!r.ok())
			std::fprintf(
			    stderr, "  %s: %s%s%s%s\n", r.run.id.c_str(), r.status.c_str(),
			    r.exitCode ? (", exit " + std::to_string(*r.exitCode)).c_str()
			               : "",
			    r.error.empty() ? "" : ": ", r.error.c_str());
	return 1;
}

/** \a names in short: the plain ones, then each dotted family as
 * "stage_ms.{input,...}.{median,...}". */
std::string namesText(const std::vector<std::string>& names)
{
	std::string plain;
	std::vector<std::pair<std::string, std::vector<std::vector<std::string>>>>
	    families;
	for (const auto& n : names)
	{
		std::vector<std::string> parts;
		std::istringstream in(n);
		for (std::string part; std::getline(in, part, '.');)
			parts.push_back(part);
		if (parts.size() == 1)
		{
			plain += (plain.empty() ? "" : ", ") + n;
			continue;
		}
		if (families.empty() || families.back().first != parts[0])
			families.push_back({parts[0], {}});
		auto& levels = families.back().second;
		levels.resize(std::max(levels.size(), parts.size() - 1));
		for (size_t k = 1; k < parts.size(); ++k)
			if (std::find(levels[k - 1].begin(), levels[k - 1].end(),
			              parts[k]) == levels[k - 1].end())
				levels[k - 1].push_back(parts[k]);
	}
	for (const auto& [first, levels] : families)
	{
		plain += ", " + first;
		for (const auto& level : levels)
		{
			plain += ".{";
			for (size_t k = 0; k < level.size(); ++k)
				plain += (k ? "," : "") + level[k];
			plain += "}";
		}
	}
	return plain;
}

/** --plot-metric, before any run: a number bims-run writes in
 * metrics.json (pipeline::metricNames), or, when the runs are scored
 * ([truth]), one of their scores (masks.* of the labels, traj.* of the
 * trajectory; their fields are checked when the results are collected). */
void checkPlotMetric(const std::string& metric, const sweep::TruthSpec& truth)
{
	const auto names = pipeline::metricNames();
	if (std::find(names.begin(), names.end(), metric) != names.end()) return;
	const auto given = [](const std::vector<std::string>& v) {
		return std::any_of(v.begin(), v.end(),
		                   [](auto& x) { return !x.empty(); });
	};
	const bool masks = given(truth.masks), traj = given(truth.trajectories);
	if ((masks && metric.rfind("masks.", 0) == 0) ||
	    (traj && metric.rfind("traj.", 0) == 0))
		return;
	throw UsageError(
	    "--plot-metric " + metric +
	    ": not a number bims-run writes in metrics.json; one of: " +
	    namesText(names) +
	    (masks ? "; or a score of the labels, masks.*" : "") +
	    (traj ? "; or a score of the trajectory, traj.*" : ""));
}
}  // namespace

std::string scoreRun(const SweepPlan& plan, const sweep::RunSpec& run,
                     const std::string& outDir)
{
	if (run.truthMasks.empty() && run.truthTrajectory.empty()) return "";
	const std::string dir = runDir(outDir, run.id);
	const std::string out = sweep::runOutDir(outDir, run.id);
	const std::string metrics = out + "/metrics.json";
	if (collectRun(run, outDir).status != "ok") return "";
	const bool masks =
	    !run.truthMasks.empty() && !upToDate(dir + "/masks.json", metrics);
	const bool traj =
	    !run.truthTrajectory.empty() && !upToDate(dir + "/traj.json", metrics);
	if (!masks && !traj) return "";
	std::string error;
	OutputInto log(dir + "/eval.txt");
	if (masks)
	{
		try
		{
			EvalMasksOptions o;
			o.gtDir = run.truthMasks;
			o.predDir = out + "/masks";
			if (plan.truth.depthValid) o.depthValid = run.rawlog.path;
			o.noPlots = true;
			o.quiet = true;
			o.json = dir + "/masks.json";
			if (plan.truth.movingValue >= 0)
				o.movingValue = plan.truth.movingValue;
			if (plan.truth.staticValue >= 0)
				o.staticValue = plan.truth.staticValue;
			if (!plan.truth.ignoreValues.empty())
				o.ignoreValues = plan.truth.ignoreValues;
			std::printf("bims-sweep: scoring the masks (bims-eval masks)\n");
			runEvalMasks(o);
		}
		catch (const std::exception& e)
		{
			error = std::string("bims-eval masks: ") + e.what();
			std::fprintf(stderr, "%s\n", error.c_str());
		}
	}
	if (traj)
	{
		try
		{
			EvalTrajOptions o;
			o.gt = run.truthTrajectory;
			o.est = out + "/trajectory.txt";
			o.json = dir + "/traj.json";
			o.plot = dir + "/traj.png";
			std::printf(
			    "bims-sweep: scoring the trajectory (bims-eval traj)\n");
			runEvalTraj(o);
		}
		catch (const std::exception& e)
		{
			const std::string t = std::string("bims-eval traj: ") + e.what();
			std::fprintf(stderr, "%s\n", t.c_str());
			error += (error.empty() ? "" : "; ") + t;
		}
	}
	if (!error.empty()) error += " (see " + dir + "/eval.txt)";
	return error;
}

namespace
{
/** Submits the jobs file as one Slurm array job: OUTDIR/slurm.sh runs
 * line SLURM_ARRAY_TASK_ID of it. Returns sbatch's job id. */
std::string submitToSlurm(const SweepOptions& opt, const SweepPlan& plan,
                          const std::string& jobsFile)
{
	const std::string dir = fs::absolute(opt.outDir).lexically_normal();
	const std::string jobs = fs::absolute(jobsFile).lexically_normal();
	const std::string script = dir + "/slurm.sh";
	writeFileAtomically(script,
	                    "#!/bin/bash\n"
	                    "# bims-sweep " +
	                        plan.name +
	                        ": Slurm array task i runs line i of the jobs file "
	                        "(docs/sweep.md)\n"
	                        "set -eu\n"
	                        "line=$(sed -n \"${SLURM_ARRAY_TASK_ID}p\" " +
	                        shellLine({jobs}) +
	                        ")\n"
	                        "exec bash -c \"$line\"\n");
	makeDirs(dir + "/slurm");
	std::vector<std::string> argv = {
	    "sbatch", "--parsable", "--array=1-" + std::to_string(plan.runs.size()),
	    "--job-name=bims-sweep", "--output=" + dir + "/slurm/%A_%a.out"};
	std::istringstream more(opt.sbatchArgs);
	for (std::string w; more >> w;) argv.push_back(w);
	argv.push_back(script);
	const std::string line = shellLine(argv);
	std::printf("bims-sweep: %s\n", line.c_str());
	std::fflush(stdout);
	FILE* p = ::popen((line + " 2>&1").c_str(), "r");
	if (!p) throw std::runtime_error("cannot run sbatch");
	std::string text;
	char buf[512];
	while (std::fgets(buf, sizeof(buf), p)) text += buf;
	const int status = ::pclose(p);
	while (!text.empty() && (text.back() == '\n' || text.back() == '\r'))
		text.pop_back();
	if (status != 0)
		throw std::runtime_error(
		    "sbatch failed (" +
		    (WIFEXITED(status) && WEXITSTATUS(status) == 127
		         ? std::string("not found: is Slurm installed here?")
		         : "exit code " + std::to_string(WEXITSTATUS(status))) +
		    ")" + (text.empty() ? "" : ": " + text));
	// --parsable: "JOBID" or "JOBID;CLUSTER"
	const std::string last = text.substr(text.rfind('\n') + 1);
	return last.substr(0, last.find(';'));
}

/** bims-sweep --collect OUTDIR: the results of an earlier sweep's runs. */
int collectSweep(const SweepOptions& opt)
{
	if (!opt.sweepFile.empty() || !opt.outDir.empty() ||
	    !opt.jobsFile.empty() || opt.dryRun || opt.slurm)
		throw UsageError(
		    "--collect OUTDIR takes no SWEEP.ini, -o, --jobs-file, "
		    "--slurm nor --dry-run");
	ResultTable t{SweepPlan::readJson(opt.collect + "/sweep.json"), {}};
	for (size_t i = 0; i < t.plan.runs.size(); i++)
		t.rows.push_back(scoreAndCollect(t.plan, i, opt.collect, nullptr));
	return report(t, opt.collect, opt.plotMetric);
}

void checkSweepOptions(const SweepOptions& opt)
{
	if (opt.sweepFile.empty())
		throw UsageError("give SWEEP.ini (or --collect OUTDIR)");
	if (opt.outDir.empty())
		throw UsageError("give the output folder: -o OUTDIR");
	if (opt.jobs < 0) throw UsageError("-j: a number of runs >= 0");
	if (opt.dryRun && (!opt.jobsFile.empty() || opt.slurm))
		throw UsageError(
		    "--dry-run writes nothing: no --jobs-file nor --slurm with it");
	if (!opt.sbatchArgs.empty() && !opt.slurm)
		throw UsageError("--sbatch goes with --slurm");
}

/** The sweep's output folder: an earlier sweep's plan and results refused,
 * or replaced; its manifest; the plan (sweep.json). */
void prepareSweepFolder(const SweepOptions& opt, const SweepPlan& plan)
{
	prepareOutputFolder(
	    opt.outDir,
	    {{"sweep.json", "results.csv", "results.md", "results.png"}, {}},
	    opt.overwrite);
	makeDirs(opt.outDir);
	// what the sweep writes into OUTDIR (each run's out/ has bims-run's)
	OutputManifest manifest(opt.outDir, "bims-sweep");
	for (const char* f :
	     {"sweep.json", "results.csv", "results.md", "results.png"})
		manifest.file(f);
	for (const auto& r : plan.runs)
		for (const char* f : {"config.ini", "log.txt"})
			manifest.file("runs/" + r.id + "/" + f);
	writePlan(plan, opt.outDir);
}

/** The runs handed to others: submitted to Slurm, or written as a jobs
 * file. */
int handOffSweep(const SweepOptions& opt, const SweepPlan& plan,
                 const std::string& program, const std::string& jobsFile)
{
	writeJobsFile(jobsFile, program, plan, opt.outDir);
	if (opt.slurm)
	{
		const std::string id = submitToSlurm(opt, plan, jobsFile);
		std::printf(
		    "bims-sweep: %zu runs submitted as Slurm array job %s (tasks' "
		    "output in %s/slurm/); when it is done: bims-sweep --collect "
		    "%s\n",
		    plan.runs.size(), id.c_str(), opt.outDir.c_str(),
		    opt.outDir.c_str());
		return 0;
	}
	std::printf(
	    "bims-sweep: %zu jobs in %s (one shell line each: e.g. "
	    "'parallel -j 4 < %s'); then bims-sweep --collect %s\n",
	    plan.runs.size(), opt.jobsFile.c_str(), opt.jobsFile.c_str(),
	    opt.outDir.c_str());
	return 0;
}

/** The line of a finished run: [done/all] ID: status, fps, time, ETA. */
void printRunDone(const SweepPlan& plan, size_t i, const RunResult& row,
                  const JobOutcome& o, size_t done, double wall, bool eta)
{
	std::string fps;
	if (std::isfinite(row.metric("fps")))
		fps = mrpt::format(", %.1f fps", row.metric("fps"));
	const size_t left = plan.runs.size() - done;
	eta = eta && left;
	std::fprintf(stderr, "[%zu/%zu] %s: %s%s, %s%s%s\n", done, plan.runs.size(),
	             plan.runs[i].id.c_str(), row.status.c_str(), fps.c_str(),
	             formatDuration(o.seconds).c_str(), eta ? ", ETA " : "",
	             eta ? formatDuration(wall / done * left).c_str() : "");
}

/** The runs here, \a workers at a time; the results table and exit code. */
int runSweepHere(const SweepOptions& opt, const SweepPlan& plan,
                 const std::string& program, size_t workers)
{
	std::vector<Job> jobs;
	for (const auto& r : plan.runs)
		jobs.push_back({runCommand(program, plan, r, opt.outDir),
		                runDir(opt.outDir, r.id) + "/log.txt"});
	std::printf(
	    "bims-sweep: %zu at a time; each run in %s/runs/ID/ (config.ini, "
	    "log.txt, out/)\n",
	    workers, opt.outDir.c_str());
	std::fflush(stdout);
	ResultTable t{plan, std::vector<RunResult>(plan.runs.size())};
	const auto start = std::chrono::steady_clock::now();
	size_t done = 0;
	PoolOptions pool;
	pool.workers = workers;
	pool.stop = opt.stop;
	pool.stopSignal = stopSignal;
	pool.onDone = [&](size_t i, const JobOutcome& o)
	{
		t.rows[i] = scoreAndCollect(plan, i, opt.outDir, &o);
		done++;
		if (opt.quiet) return;
		const double wall = std::chrono::duration<double>(
		                        std::chrono::steady_clock::now() - start)
		                        .count();
		printRunDone(plan, i, t.rows[i], o, done, wall,
		             !(opt.stop && *opt.stop));
	};
	const auto outcomes = runJobs(jobs, pool);
	for (size_t i = 0; i < outcomes.size(); i++)
		if (!outcomes[i].started)
			t.rows[i] = collectRun(plan.runs[i], opt.outDir, &outcomes[i]);
	const int code = report(t, opt.outDir, opt.plotMetric);
	if (opt.stop && *opt.stop)
	{
		const int sig = stopSignal();
		std::fprintf(stderr,
		             "bims-sweep: interrupted: %zu of %zu runs not started\n",
		             plan.runs.size() - done, plan.runs.size());
		return 128 + (sig ? sig : SIGINT);
	}
	return code;
}
}  // namespace

int runSweep(const SweepOptions& opt)
{
	if (!opt.collect.empty()) return collectSweep(opt);
	checkSweepOptions(opt);
	const std::string jobsFile = opt.slurm && opt.jobsFile.empty()
	                                 ? opt.outDir + "/jobs.txt"
	                                 : opt.jobsFile;
	const SweepSpec spec = SweepSpec::load(opt.sweepFile);
	checkPlotMetric(opt.plotMetric, spec.truth);
	std::vector<std::string> inputs = {spec.file};
	for (const auto* list : {&spec.configs, &spec.rawlogs})
		for (const auto& f : *list) inputs.push_back(f.path);
	checkOutputsSpareInputs(inputs, {opt.outDir});
	if (!jobsFile.empty()) checkOutputsSpareInputs(inputs, {jobsFile});
	const SweepPlan plan = SweepPlan::make(spec);

	const std::string program = executableDir() + "/bims-run";
	if (access(program.c_str(), X_OK) != 0)
		throw std::runtime_error("bims-run not found beside bims-sweep (" +
		                         program + ")");
	const size_t workers =
	    opt.jobs > 0 ? static_cast<size_t>(opt.jobs)
	                 : std::max(1u, std::thread::hardware_concurrency());
	std::printf(
	    "bims-sweep: %s: %zu runs (%zu configs x %zu [grid] "
	    "combinations x %zu rawlogs)\n",
	    plan.name.c_str(), plan.runs.size(), spec.configs.size(),
	    plan.runs.size() / spec.configs.size() / spec.rawlogs.size(),
	    spec.rawlogs.size());
	if (opt.dryRun)
	{
		for (const auto& r : plan.runs)
			std::printf(
			    "%s: %s\n", r.id.c_str(),
			    shellLine(runCommand(program, plan, r, opt.outDir)).c_str());
		std::printf("bims-sweep: dry run, nothing written\n");
		return 0;
	}
	prepareSweepFolder(opt, plan);
	if (!jobsFile.empty()) return handOffSweep(opt, plan, program, jobsFile);
	return runSweepHere(opt, plan, program, workers);
}

}  // namespace bims::apps
