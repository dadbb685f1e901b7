// bims-import-stray's run (docs/eval.md): the options checked, the
// experiment .ini read, the import (importStray) and its report on stdout.
// The program's main only reads its command line into
// StrayImportRunOptions and calls runStrayImport.
#pragma once

#include <bims/common/progress.h>
#include <bims/eval/stray_import.h>

#include <optional>
#include <string>

namespace bims::apps
{
/** What bims-import-stray's command line gives (nullopt: not given). */
struct StrayImportRunOptions
{
	std::string folder;                 ///< the Stray Scanner capture
	std::string out;                    ///< output rawlog
	std::optional<std::string> config;  ///< experiment .ini
	size_t max_frames = 0;              ///< only the first N frames (0: all)
	int gz = 1;                         ///< gzip level of the rawlog (0: plain)
	bool progress = true;               ///< progress line on stderr
};

/** The lines bims-import-stray prints on stdout after importing into
 * \a out: frames (size, colour or not), IMU samples, the confidence
 * threshold and the share of depth readings it dropped, the reference
 * trajectory's poses and the frames left out of it. */
std::string strayImportReport(const std::string& out,
                              const eval::StrayImportSummary& sum);

/** bims-import-stray's work without its terminal: checks the options
 * (UsageError; no output may be an input), reads the config (a note on
 * stderr without one) and imports, reporting to \a progress (the Python
 * module's import_stray). */
eval::StrayImportSummary importStrayChecked(const StrayImportRunOptions& o,
                                            const ProgressCallback& progress);

/** bims-import-stray: importStrayChecked with the progress line, then
 * prints strayImportReport. Returns the program's exit code (0); errors
 * are thrown. */
int runStrayImport(const StrayImportRunOptions& o);

}  // namespace bims::apps
