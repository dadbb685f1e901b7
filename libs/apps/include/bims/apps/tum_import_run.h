// bims-import-tum's run (docs/eval.md): the options checked, the
// experiment .ini read, optionally synthetic IMU readings from the ground
// truth, the import (importTum) and its report on stdout. The program's
// main only reads its command line into ImportRunOptions and calls
// runImport.
#pragma once

#include <bims/common/progress.h>
#include <bims/eval/tum_import.h>
#include <bims/io/trajectory.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/obs/CObservation.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace bims::apps
{
/** IMU readings synthesised from the ground truth \a gt (T_WC of the
 * camera), labelled \a imuLabel, with the [calibration] of \a calibration
 * (nullptr: none) and \a seed: libs/sim's sim::synthesizeImportImu unless
 * a caller gives another (a test's). */
using ImuSynthesis = std::function<std::vector<mrpt::obs::CObservation::Ptr>(
    const Trajectory& gt, const std::string& imuLabel,
    const mrpt::config::CConfigFileBase* calibration, uint64_t seed)>;

/** What bims-import-tum's command line gives (nullopt: not given). */
struct ImportRunOptions
{
	std::string folder;                 ///< TUM RGB-D folder
	std::string out;                    ///< output rawlog
	std::optional<std::string> config;  ///< experiment .ini
	bool bonn_gt = false;    ///< the ground truth is Bonn's marker pose
	size_t max_frames = 0;   ///< import only the first N frames (0: all)
	int gz = 1;              ///< gzip level of the rawlog (0: plain)
	bool synth_imu = false;  ///< add synthetic IMU readings
	uint64_t seed = 1;       ///< random seed of synth_imu
	bool progress = true;    ///< progress line on stderr
	ImuSynthesis
	    synthesize;  ///< for synth_imu (empty: sim::synthesizeImportImu)
};

/** The lines bims-import-tum prints on stdout after importing into
 * \a out: frames, IMU observations (\a synthetic: marked so) and
 * accelerometer samples with their labels (\a params), then the ground
 * truth's poses (\a bonnConverted: marked so) or its absence. */
std::string importReport(const std::string& out, const eval::ImportSummary& sum,
                         bool synthetic, bool bonnConverted,
                         const eval::ImportParams& params);

/** What an import into a rawlog gave: its summary, the parameters it
 * read and whether the ground truth was Bonn's marker pose, converted. */
struct TumImport
{
	eval::ImportSummary summary;
	eval::ImportParams params;
	bool bonnConverted = false;
};

/** bims-import-tum's work without its terminal: checks the options
 * (UsageError; no output may be an input), reads the config (a note on
 * stderr without one), synthesises the IMU readings if asked and imports,
 * reporting to \a progress (the Python module's import_tum). */
TumImport importTumChecked(const ImportRunOptions& o,
                           const ProgressCallback& progress);

/** bims-import-tum: importTumChecked with the progress line, then prints
 * importReport. Returns the
 * program's exit code (0); errors are thrown. */
int runImport(const ImportRunOptions& o);

}  // namespace bims::apps
