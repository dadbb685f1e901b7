// bims-import-bag's run (docs/import-bag.md): the options checked, the
// experiment .ini read, the import (importBag) and its report on stdout.
// The program's main only reads its command line into BagImportRunOptions
// and calls runBagImport.
#pragma once

#include <bims/bag/bag_import.h>
#include <bims/common/progress.h>

#include <optional>
#include <string>
#include <vector>

namespace bims::apps
{
/** What bims-import-bag's command line gives (nullopt: not given). */
struct BagImportRunOptions
{
	std::vector<std::string> bags;      ///< ROS 1 or 2 bags, read as one
	std::string out;                    ///< output rawlog
	std::optional<std::string> config;  ///< experiment .ini
	std::optional<std::string> layout;  ///< --layout (overrides the .ini's)
	/** --depth-units: metres per unit of an rs-sdk recording's depth
	 * (overrides the .ini's and the recording's) */
	std::optional<double> depthUnits;
	size_t max_frames = 0;    ///< only the first N frames (0: all)
	int gz = 1;               ///< gzip level of the rawlog (0: plain)
	bool progress = true;     ///< progress line on stderr
	bool listTopics = false;  ///< --topics: list them, no import
};

/** The lines bims-import-bag prints on stdout after importing into \a out:
 * the frames (size, encodings, the intrinsics and where they came from),
 * the images left out and why, the IMU samples with their channels and
 * labels. */
std::string bagImportReport(const std::string& out,
                            const bag::BagImportSummary& sum,
                            const bag::BagImportParams& params);

/** What an import of bags gave: its summary and the parameters it read. */
struct BagImport
{
	bag::BagImportSummary summary;
	bag::BagImportParams params;
};

/** bims-import-bag's import without its terminal: checks the options
 * (UsageError; no output may be an input), reads the config and imports,
 * reporting to \a progress (the Python module's import_bag). */
BagImport importBagChecked(const BagImportRunOptions& o,
                           const ProgressCallback& progress);

/** bims-import-bag: importBagChecked with the progress line, then prints
 * bagImportReport (or, with listTopics, the bags' topics). Returns the
 * program's exit code (0); errors are thrown. */
int runBagImport(const BagImportRunOptions& o);

}  // namespace bims::apps
