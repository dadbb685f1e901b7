// A sweep of bims-run experiments (docs/sweep.md): SWEEP.ini read and
// checked, the runs it asks for (experiment configs x [grid] overrides x
// rawlogs), each run's derived config.ini, the plan file sweep.json and the
// jobs file of the cluster mode.
#pragma once

#include <bims/io/json.h>

#include <string>
#include <utility>
#include <vector>

namespace bims::sweep
{
/** One [grid] key of SWEEP.ini: an experiment key and its values. */
struct GridAxis
{
	std::string name;  ///< "section.key" as written, e.g. grids.voxel_size
	std::string section, key;
	std::vector<std::string> values;  ///< in the order written
	std::string from = "grid";        ///< its section of SWEEP.ini (or "set")
};

/** A file listed in SWEEP.ini: as written, and its path (relative ones
 * resolved against SWEEP.ini's folder). */
struct ListedFile
{
	std::string written, path;
};

/** What a sweep's runs are scored against ([truth] of SWEEP.ini): per
 * rawlog, its moving-pixel labels and/or its trajectory (each "" when
 * none), and how the labels read (bims-eval masks' options). */
struct TruthSpec
{
	/** One per rawlog, in the rawlogs' order ("": not scored so). */
	std::vector<std::string> masks, trajectories;
	/** The labels' values (bims-eval masks --moving-value, --static-value,
	 * --ignore-values); -1 / "": not given (the labels' contract). */
	int movingValue = -1, staticValue = -1;
	std::string ignoreValues;
	/** Only the pixels with depth in the rawlog's scans are scored
	 * (bims-eval masks --depth-valid IN.rawlog). */
	bool depthValid = true;
	bool any() const;
};

/** SWEEP.ini as read: [sweep] configs, rawlogs, frames, name; [grid];
 * [set]; [truth]. */
struct SweepSpec
{
	std::string file;  ///< SWEEP.ini
	std::string name;  ///< [sweep] name (default: the file's stem)
	std::vector<ListedFile> configs, rawlogs;
	std::string frames;  ///< bims-run --frames A:B ("": every frame)
	/** The keys that vary: two or more values ([grid]), in MRPT's order
	 * (by name). */
	std::vector<GridAxis> grid;
	/** The keys set to one value for every run: [set], and the [grid] keys
	 * given one value; by name. */
	std::vector<GridAxis> constants;
	TruthSpec truth;

	/** Reads and checks SWEEP.ini: its syntax (checkIniFile), no section
	 * but [sweep], [grid], [set] and [truth], no unknown key, configs and
	 * rawlogs given and present, frames A:B, grid keys "section.key" with a
	 * comma-separated list of distinct non-empty values, [set] keys
	 * "section.key" with one value (not also in [grid]), [truth] masks and
	 * trajectory "auto" (the simulator's RAWLOG_gt/masks,
	 * RAWLOG_gt/groundtruth.txt) or one path per rawlog, present. Throws
	 * ConfigError naming the file, the section and the key. */
	static SweepSpec load(const std::string& path);
};

/** One run: a config with one value of each grid key, on one rawlog. */
struct RunSpec
{
	/** Short readable name, unique in the sweep: the run's number, then
	 * what varies (the config's stem when there are several, key=value per
	 * grid key, the rawlog's stem when there are several), e.g.
	 * "3_voxel_size=0.1_variant=fused". Its folder is OUTDIR/runs/ID
	 * (runDir): config.ini, log.txt, and bims-run's outputs in out/. */
	std::string id;
	ListedFile config, rawlog;
	/** (grid key name, value), one per grid key, in the grid's order. */
	std::vector<std::pair<std::string, std::string>> overrides;
	/** The derived config.ini: the config with the constants and the
	 * overrides set (through MRPT's CConfigFileMemory; comments and the
	 * other keys kept). */
	std::string configText;
	/** The rawlog's labels and trajectory ("": none), from [truth]. */
	std::string truthMasks, truthTrajectory;
};

/** Every run of a sweep, checked. */
struct SweepPlan
{
	std::string name, sweepFile, frames;
	std::vector<std::string> gridKeys;
	/** (key, value) set for every run ([set], one-value [grid] keys): in
	 * no run id nor legend, listed once. */
	std::vector<std::pair<std::string, std::string>> constants;
	std::vector<RunSpec> runs;
	TruthSpec truth;  ///< masks and trajectories: see the runs'

	/** The runs of \a spec: configs (outer) x grid combinations x rawlogs
	 * (inner). Every config, every override alone and every combination
	 * (derived config) is read by bims-run's loader
	 * (pipeline::ExperimentConfig), so an unknown section or key or a bad
	 * value is a ConfigError naming SWEEP.ini, the [grid] key and value,
	 * and the config, before any run starts. */
	static SweepPlan make(const SweepSpec& spec);

	/** sweep.json: what bims-sweep --collect reads (configText not kept). */
	Json toJson() const;
	/** Reads \a path (a sweep.json); throws naming it. */
	static SweepPlan readJson(const std::string& path);
};

/** "grids.decay=raycast, pipeline.variant=fused" (empty without). */
std::string constantsText(const SweepPlan& plan);

/** The names run ids and plot labels give the grid keys: the key alone
 * ("voxel_size") unless two sections share it ("grids.voxel_size"). */
std::vector<std::string> shortGridKeys(const std::vector<std::string>& keys);

/** OUTDIR/runs/ID. */
std::string runDir(const std::string& outDir, const std::string& id);
/** OUTDIR/runs/ID/out: bims-run's output folder (not the run's folder:
 * bims-run refuses an output folder holding its config). */
std::string runOutDir(const std::string& outDir, const std::string& id);

/** bims-run's command line for \a run: PROGRAM RUN/config.ini IN.rawlog
 * [--frames A:B] -o RUN/out -q (absolute paths). */
std::vector<std::string> runCommand(const std::string& program,
                                    const SweepPlan& plan, const RunSpec& run,
                                    const std::string& outDir);

/** Writes OUTDIR/sweep.json and each run's folder with its config.ini; an
 * earlier RUN/out/metrics.json is removed (it belongs to another plan). */
void writePlan(const SweepPlan& plan, const std::string& outDir);

/** \a argv as one line for sh/bash, every word quoted when needed. */
std::string shellLine(const std::vector<std::string>& argv);

/** The jobs file: one shell line per run, runCommand(...) with its output
 * into RUN/log.txt, for GNU parallel or a Slurm array. */
void writeJobsFile(const std::string& path, const std::string& program,
                   const SweepPlan& plan, const std::string& outDir);

}  // namespace bims::sweep
