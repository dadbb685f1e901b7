// The results of a sweep: each run's metrics.json (and any other JSON file
// in its folder, e.g. bims-eval's scores) gathered into results.csv,
// results.md and the plot results.png.
#pragma once

#include <bims/eval/plots.h>
#include <bims/sweep/plan.h>
#include <bims/sweep/processes.h>

#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace bims::sweep
{
/** What one run gave. */
struct RunResult
{
	RunSpec run;  ///< id, config, rawlog, overrides
	/** metrics.json's "status" (ok, error, interrupted); else "failed" (it
	 * ran and wrote none), "not run" (the sweep stopped before it) or
	 * "missing" (collected: no metrics.json yet). */
	std::string status;
	std::string error;  ///< metrics.json's "error", or what went wrong
	std::optional<int> exitCode;    ///< bims-run's, when this sweep ran it
	std::optional<double> seconds;  ///< its wall time, idem
	/** Every number of metrics.json by its path ("fps",
	 * "stage_ms.total.median"), then those of the JSON files in the run's
	 * folder prefixed by the file's stem ("ate.ate.error_m.rmse"); NaN for
	 * null. */
	std::vector<std::pair<std::string, double>> metrics;

	bool ok() const { return status == "ok" && exitCode.value_or(0) == 0; }
	/** The metric's value, NaN when absent. */
	double metric(const std::string& name) const;
};

/** Reads OUTDIR/runs/ID/out/metrics.json (bims-run's) and the *.json
 * files of OUTDIR/runs/ID (by name, e.g. bims-eval's); \a outcome is the
 * run's when this sweep ran it. */
RunResult collectRun(const RunSpec& run, const std::string& outDir,
                     const JobOutcome* outcome = nullptr);

/** Every run of a sweep. */
struct ResultTable
{
	SweepPlan plan;
	std::vector<RunResult> rows;  ///< one per plan.runs, in order
	/** The metric names of all rows, in order of first appearance. */
	std::vector<std::string> metricNames() const;
	size_t failures() const;
};

/** One row per run: id, config, rawlog, each grid key, each constant,
 * status, exit_code, run_seconds, every metric, error (RFC 4180 quoting). */
std::string csvText(const ResultTable& t);

/** A markdown table of the runs (after a line listing the constants once)
 * with the main columns: id, config, rawlog, the grid keys, status, exit code,
 * seconds, frames, fps, wall and CPU seconds, peak memory, the pipeline's
 * median ms per frame, \a plotMetric, and the scores of other JSON files (names
 * ending in rmse, f1, iou, precision, recall); then the failed runs with their
 * errors. */
std::string markdownText(const ResultTable& t, const std::string& plotMetric);

/** The chart of \a metric per run: one group per combination of the
 * grid's values, one bar per config and rawlog (named by the file's stem,
 * or as written when two share it); the constants listed once under the
 * axis; runs that are not ok have no value. Throws std::invalid_argument
 * naming the metrics there are when no run has \a metric but some have
 * others. */
eval::GroupedBars resultsChart(const ResultTable& t, const std::string& metric);

/** The top of a metric's axis when its values have one: 1 for a score or a
 * share (a name whose last part is f1, precision, recall, iou or
 * ends in _fraction); none otherwise. */
std::optional<double> metricAxisTop(const std::string& metric);

/** resultsChart drawn (eval::plotGroupedBars). */
cv::Mat plotResults(const ResultTable& t, const std::string& metric);

/** Writes OUTDIR/results.csv, results.md, then results.png. */
void writeResults(const ResultTable& t, const std::string& outDir,
                  const std::string& plotMetric);

}  // namespace bims::sweep
