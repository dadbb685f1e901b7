// bims-sim's run (docs/sim.md): a scene .ini rendered into a rawlog and its
// ground truth, or IMU readings synthesised from a TUM trajectory. The
// program's main only reads its command line into SimOptions and calls
// runSim.
#pragma once

#include <bims/sim/simulator.h>

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

namespace bims::apps
{
/** What bims-sim's command line gives (nullopt: option not given). */
struct SimOptions
{
	std::optional<std::string> scene;       ///< scene .ini
	std::string out;                        ///< output rawlog
	uint64_t seed = 1;                      ///< random seed
	std::optional<int> max_frames;          ///< overrides [sim] frames
	std::optional<std::string> resolution;  ///< overrides [camera] resolution
	/** synthesise only IMU data from this TUM trajectory (T_WC) */
	std::optional<std::string> imu_from_tum;
	/** with imu_from_tum: .ini with [imu] and [calibration] */
	std::optional<std::string> config;
	std::optional<int> preview;  ///< also write OUT_gt/preview.png of frame N
	bool overwrite = false;      ///< replace an earlier run's ground truth
	bool progress = true;        ///< progress bar on stderr
	/** when it turns true (bims::installStopSignals), the simulation ends
	 * after the current frame */
	const std::atomic<bool>* stop = nullptr;
};

/** The scene run of \a o: its scene .ini with --max-frames and
 * --resolution applied. Throws UsageError for a bad --max-frames,
 * --resolution or --preview (a frame index out of the run). */
sim::SimConfig simConfigFor(const SimOptions& o);

/** IMU readings synthesised from the TUM trajectory \a tum (T_WC) with
 * \a seed and the [imu] and [calibration] of \a iniPath ("": the default
 * IMU): the rawlog \a out, the truth in groundTruthDirFor(out)/imu.txt.
 * Returns the line bims-sim prints on stderr (with its newline). */
std::string imuFromTum(const std::string& tum, const std::string& out,
                       uint64_t seed, const std::string& iniPath);

/** The line bims-sim prints on stderr after a simulation of \a cfg (with
 * its newline). */
std::string simSummary(const sim::SimStats& st, const sim::SimConfig& cfg);

/** bims-sim: checks the options (UsageError; no output may be an input,
 * an earlier run's ground truth is refused unless overwrite), then runs
 * the IMU synthesis or the simulation and prints its summary on stderr.
 * Returns the program's exit code (0, or 128 + the signal when stopped);
 * errors are thrown. */
int runSim(const SimOptions& o);

}  // namespace bims::apps
