#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>
#include <bims/apps/progress_bar.h>
#include <bims/apps/sweep_run.h>
#include <bims/common/share.h>
#include <bims/pipeline/run.h>
#include <bims/sweep/plan.h>
#include <bims/sweep/processes.h>
#include <bims/sweep/results.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
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
namespace
{
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
 * metrics.json (pipeline::metricNames). */
void checkPlotMetric(const std::string& metric)
{
	const auto names = pipeline::metricNames();
	if (std::find(names.begin(), names.end(), metric) == names.end())
		throw UsageError("--plot-metric " + metric +
		                 ": not a number bims-run writes in metrics.json; "
		                 "one of: " +
		                 namesText(names));
}
}  // namespace

int runSweep(const SweepOptions& opt)
{
	if (!opt.collect.empty())
	{
		if (!opt.sweepFile.empty() || !opt.outDir.empty() ||
		    !opt.jobsFile.empty() || opt.dryRun)
			throw UsageError(
			    "--collect OUTDIR takes no SWEEP.ini, -o, --jobs-file nor "
			    "--dry-run");
		ResultTable t{SweepPlan::readJson(opt.collect + "/sweep.json"), {}};
		for (const auto& r : t.plan.runs)
			t.rows.push_back(collectRun(r, opt.collect));
		return report(t, opt.collect, opt.plotMetric);
	}
	if (opt.sweepFile.empty())
		throw UsageError("give SWEEP.ini (or --collect OUTDIR)");
	if (opt.outDir.empty())
		throw UsageError("give the output folder: -o OUTDIR");
	if (opt.jobs < 0) throw UsageError("-j: a number of runs >= 0");
	if (opt.dryRun && !opt.jobsFile.empty())
		throw UsageError("--dry-run writes nothing: no --jobs-file with it");
	checkPlotMetric(opt.plotMetric);

	const SweepSpec spec = SweepSpec::load(opt.sweepFile);
	std::vector<std::string> inputs = {spec.file};
	for (const auto* list : {&spec.configs, &spec.rawlogs})
		for (const auto& f : *list) inputs.push_back(f.path);
	checkOutputsSpareInputs(inputs, {opt.outDir});
	if (!opt.jobsFile.empty()) checkOutputsSpareInputs(inputs, {opt.jobsFile});
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
	// an earlier sweep's plan and results are refused, or replaced
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
	if (!opt.jobsFile.empty())
	{
		writeJobsFile(opt.jobsFile, program, plan, opt.outDir);
		std::printf(
		    "bims-sweep: %zu jobs in %s (one shell line each: e.g. "
		    "'parallel -j 4 < %s'); then bims-sweep --collect %s\n",
		    plan.runs.size(), opt.jobsFile.c_str(), opt.jobsFile.c_str(),
		    opt.outDir.c_str());
		return 0;
	}

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
		t.rows[i] = collectRun(plan.runs[i], opt.outDir, &o);
		done++;
		if (opt.quiet) return;
		char fps[32] = "";
		if (std::isfinite(t.rows[i].metric("fps")))
			std::snprintf(fps, sizeof(fps), ", %.1f fps",
			              t.rows[i].metric("fps"));
		const double wall = std::chrono::duration<double>(
		                        std::chrono::steady_clock::now() - start)
		                        .count();
		const size_t left = plan.runs.size() - done;
		const bool eta = left && !(opt.stop && *opt.stop);
		std::fprintf(stderr, "[%zu/%zu] %s: %s%s, %s%s%s\n", done,
		             plan.runs.size(), plan.runs[i].id.c_str(),
		             t.rows[i].status.c_str(), fps,
		             formatDuration(o.seconds).c_str(), eta ? ", ETA " : "",
		             eta ? formatDuration(wall / done * left).c_str() : "");
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

}  // namespace bims::apps
