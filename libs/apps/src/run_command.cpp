// bims-run's command: the options of its command line into a run
// (runExperiment) and its report.
#include <bims/apps/app.h>
#include <bims/apps/frame_range_option.h>
#include <bims/apps/input_kind.h>
#include <bims/apps/output_checks.h>
#include <bims/apps/progress_bar.h>
#include <bims/apps/run_command.h>
#include <bims/apps/run_report.h>
#include <bims/common/choice.h>
#include <bims/io/rawlog.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace bims::apps
{
using pipeline::formatSummary;
using pipeline::runExperiment;
using pipeline::RunOptions;
using pipeline::runOutputLayout;

using pipeline::Variant;

std::optional<int> printConfigIfAsked(int argc, char** argv)
{
	std::vector<std::string> args(argv + 1, argv + argc);
	const auto it = std::find(args.begin(), args.end(), "--print-config");
	if (it == args.end()) return std::nullopt;
	args.erase(it);
	if (args.size() > 1 || (args.size() == 1 && args[0].rfind("-", 0) == 0))
		throw UsageError(
		    "--print-config takes at most one experiment .ini and nothing "
		    "else: bims-run --print-config [CONFIG.ini]");
	ExperimentConfig cfg;
	if (!args.empty()) cfg.loadFromFile(args[0]);
	std::printf("%s", cfg.effectiveIni().c_str());
	return 0;
}

void applyVariantOption(ExperimentConfig& cfg, const std::string& name)
{
	try
	{
		cfg.setVariant(parseChoice<Variant>(name));
	}
	catch (const std::invalid_argument& e)
	{
		throw UsageError(std::string("--variant: ") + e.what());
	}
}

int runExitCode(const RunSummary& s, int signal)
{
	if (s.interrupted) return 128 + (signal ? signal : SIGINT);
	return s.error.empty() ? 0 : 1;
}

int runFromCommandLine(const RunCommand& c)
{
	// every input before any output: a typo in the second rawlog is an
	// error before the first is run and before OUTDIR is made; an input of
	// the wrong kind names the command to use
	checkRunInputKinds(c.config, c.rawlogs);
	for (const auto& r : c.rawlogs) checkRawlogPath(r);
	auto inputs = c.rawlogs;
	inputs.push_back(c.config);
	checkOutputsSpareInputs(inputs, {c.outDir});

	ExperimentConfig cfg;
	cfg.loadFromFile(c.config);
	if (c.variant) applyVariantOption(cfg, *c.variant);
	RunOptions opt;
	opt.rawlogs = c.rawlogs;
	opt.outDir = c.outDir;
	opt.laterFiles = {"report.md"};  // writeRunReport, after the run
	ProgressBar bar("bims-run", 0, c.progress);
	opt.progress = bar.callback();
	if (c.installStop) opt.stop = &c.installStop();
	opt.frames =
	    frameRangeOption(c.frames, opt.rawlogs, cfg.ego.sensors.rgbd_label);
	const size_t cleared =
	    prepareOutputFolder(opt.outDir, runOutputLayout(), c.overwrite);
	if (cleared)
		std::fprintf(stderr,
		             "bims-run: --overwrite: removed the %zu files of an "
		             "earlier run from %s\n",
		             cleared, opt.outDir.c_str());
	const auto sum = runExperiment(cfg, opt);
	std::printf("%s", formatSummary(sum).c_str());
	// the one page to read first (a run stopped before metrics.json has
	// none)
	bool report = false;
	if (std::filesystem::exists(opt.outDir + "/metrics.json"))
	{
		try
		{
			writeRunReport({opt.outDir, opt.rawlogs, c.config,
			                choiceName(cfg.ego.odometry.mode), cfg.input});
			report = true;
		}
		catch (const std::exception& e)
		{
			std::fprintf(stderr, "bims-run: warning: no report.md: %s\n",
			             e.what());
		}
	}
	std::printf(
	    "outputs in %s/ (%strajectory.txt, masks/, metrics.json, ...)\n",
	    opt.outDir.c_str(), report ? "report.md, " : "");
	if (!sum.error.empty())
		std::fprintf(stderr, "bims-run: error: %s\n", sum.error.c_str());
	const int sig = stopSignal();
	if (sum.interrupted)
		std::fprintf(stderr,
		             "bims-run: interrupted by %s after %zu frames: their "
		             "outputs are complete, metrics.json says \"status\": "
		             "\"interrupted\"\n",
		             sig == SIGTERM ? "SIGTERM" : "SIGINT",
		             sum.framesProcessed);
	return runExitCode(sum, sig);
}

}  // namespace bims::apps
