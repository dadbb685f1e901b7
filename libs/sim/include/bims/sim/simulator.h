// The whole simulation: a scene .ini -> an MRPT rawlog (observations format:
// CObservation3DRangeScan + CObservationIMU, time-ordered) and its ground
// truth.
//
// Scene .ini sections (all optional except [sim]; unknown sections or keys are
// errors naming the file, section and key):
//   [sim] [camera] [depth] [rgb] [imu] [calibration] [motion] [room]
//   and any number of moving objects in sections named pendulum*, box*,
//   walker*.
// See docs/sim.md for every key, unit and default.
#pragma once

#include <bims/common/progress.h>
#include <bims/io/output_paths.h>
#include <bims/sim/imu.h>
#include <bims/sim/motion.h>
#include <bims/sim/objects.h>
#include <bims/sim/renderer.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace bims::sim
{
/** [sim]: sequence-level settings. */
struct SequenceParams
{
	int frames = 150;                ///< number of RGB-D frames
	double fps = 30;                 ///< RGB-D frame rate [Hz]
	std::string rgbdLabel = "RGBD";  ///< sensorLabel of the 3D range scans
	double startTime =
	    1325376000.0;  ///< UNIX time of frame 0 [s] (2012-01-01T00:00:00Z)
	int gzLevel = 1;   ///< gzip level of the rawlog (0 = plain)
	bool pixelLabels = true;  ///< also store the mask as the scans' pixel
	                          ///< labels ("static", "moving")
};

/** Everything a scene .ini describes. */
struct SimConfig
{
	std::string file;  ///< the .ini it was read from
	SequenceParams seq;
	CameraParams camera;
	DepthParams depth;
	RgbParams rgb;
	ImuParams imu;
	HandheldMotionParams motion;
	RoomParams room;
	std::vector<std::pair<std::string, PendulumParams>>
	    pendulums;  ///< (section, params)
	std::vector<std::pair<std::string, SlidingBoxParams>> boxes;
	std::vector<std::pair<std::string, WalkerParams>> walkers;

	/** Reads and validates a scene file; throws ConfigError (file, section,
	 * key) on unknown/missing/out-of-range entries, std::runtime_error if the
	 * file cannot be read. */
	static SimConfig load(const std::string& iniPath);
	/** Room, furniture and moving objects (ids 1.. in the order pendulums,
	 * boxes, walkers, each sorted by section name). */
	Scene buildScene() const;
};

/** Figures of one run. */
struct SimStats
{
	size_t frames = 0, imuSamples = 0;
	double seconds = 0;         ///< wall-clock time of the whole run [s]
	double renderSeconds = 0;   ///< time spent rendering [s]
	double cpuSeconds = 0;      ///< CPU time of the process during the run [s]
	                            ///< (single-threaded: the work done)
	double movingFraction = 0;  ///< mean fraction of pixels on moving objects
	std::string gtDir;          ///< ground-truth folder
	bool interrupted = false;   ///< stopped early by \a stop (frames < asked)
};

/** Every file bims-sim writes into the ground-truth folder (runSimulation,
 * saveImuTruth): an earlier run's are refused or cleared by
 * bims::prepareOutputFolder (bims-sim --overwrite). */
const bims::OutputFolderLayout& groundTruthLayout();

/** Runs the simulation and writes \a outRawlog and
 * groundTruthDirFor(outRawlog)/: groundtruth.txt (T_WC per frame, TUM), imu.txt
 * (true rates, forces, fields, biases), objects.txt (object poses per frame),
 * masks/NNNNNN.png, calibration.ini. Deterministic in (config, seed). \param
 * progress receives the frames rendered (none: silent). \param previewFrame if
 * >= 0, also writes preview.png (RGB | depth | mask) of that frame into the
 * ground-truth folder. \param stop when it turns true (e.g. the program's stop
 * signals), the run ends after the current frame and writes everything for the
 * frames done: a complete, shorter sequence (the IMU up to half a frame past
 * its last frame, as a full run), SimStats::interrupted set. */
SimStats runSimulation(const SimConfig& cfg, const std::string& outRawlog,
                       uint64_t seed, const ProgressCallback& progress = {},
                       int previewFrame = -1,
                       const std::atomic<bool>* stop = nullptr);

}  // namespace bims::sim
