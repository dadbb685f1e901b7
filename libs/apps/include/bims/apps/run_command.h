// bims-run's command: its command line's values into a run
// (pipeline::runExperiment), the report and the exit code. The program's main
// only declares the options and calls runFromCommandLine.
#pragma once

#include <bims/pipeline/config.h>
#include <bims/pipeline/run.h>

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace bims::apps
{
using pipeline::ExperimentConfig;
using pipeline::RunSummary;

/** bims-run --print-config [CONFIG.ini]: prints the effective .ini (of
 * CONFIG.ini, or of the built-in defaults) and returns 0; nullopt when the
 * command line has no --print-config. Throws UsageError when it has more
 * than one other word. */
std::optional<int> printConfigIfAsked(int argc, char** argv);

/** What bims-run's command line gives (bims-run CONFIG.ini IN.rawlog...
 * -o OUTDIR). */
struct RunCommand
{
	std::string config;                ///< experiment .ini
	std::vector<std::string> rawlogs;  ///< read one after the other
	std::string outDir;                ///< output folder
	std::string frames;                ///< --frames A:B ("": all)
	/** --variant NAME, overriding [pipeline] variant */
	std::optional<std::string> variant;
	bool overwrite = false;  ///< clear an earlier run's outputs in outDir
	bool progress = true;    ///< progress line on stderr
	/** Called once the config is read, before the frame range is checked:
	 * the flag that stops the run after the current frame when it turns
	 * true (main(): bims::installStopSignals; a signal before it still ends
	 * the program at once). Empty: never stopped. */
	std::function<const std::atomic<bool>&()> installStop;
};

/** --variant \a name: cfg.setVariant of the parsed name; a bad name is a
 * UsageError "--variant: ..." naming the choices. */
void applyVariantOption(ExperimentConfig& cfg, const std::string& name);

/** bims-run's exit code for a finished run: 128 + \a signal when it was
 * interrupted (SIGINT's when \a signal is 0), 1 when an error stopped it,
 * else 0. */
int runExitCode(const RunSummary& s, int signal);

/** bims-run: checks that no output is an input, reads the config (and
 * --variant), checks the frame range, prepares the output folder (the
 * --overwrite note on stderr), runs the experiment, prints the summary and
 * where the outputs are, and the error or the interruption on stderr
 * (stopSignal() names the signal). Returns the exit code (runExitCode). */
int runFromCommandLine(const RunCommand& c);

}  // namespace bims::apps
