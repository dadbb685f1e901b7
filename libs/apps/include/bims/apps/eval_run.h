// bims-eval's sub-commands (docs/eval.md): trajectory, mask, depth
// consistency and attitude figures. The program's main picks the
// sub-command; each one's command line (apps/eval/cmd_*.cpp) is read into
// its options here and run by one function.
#pragma once

#include <bims/io/image_file.h>

#include <optional>
#include <string>

namespace bims::apps
{
using bims::ImageLimits;

/** What bims-eval traj's command line gives (nullopt: not given). */
struct EvalTrajOptions
{
	std::string gt;                   ///< ground-truth trajectory (TUM)
	std::string est;                  ///< estimated trajectory (TUM)
	std::optional<std::string> plot;  ///< PNG plot (default: EST_traj.png)
	bool noPlot = false;              ///< write no plot
	std::optional<std::string> json;  ///< the figures as JSON
	double maxDt = 0.02;  ///< max time difference to associate poses [s]
	double delta = 1.0;   ///< RPE interval [s]
	double offset = 0.0;  ///< time offset added to EST stamps [s]
	/** a frame whose translation differs from the reference's by more is
	 * counted [m] */
	double jumpM = 0.03;
};

/** bims-eval traj: ATE after Horn's alignment, RPE and the frame-to-frame
 * figures (eval::computeJumps), printed on stdout, the plot and the JSON.
 * Checks that no output is an input and the options' ranges (UsageError).
 * Returns the exit code (0); errors are thrown. */
int runEvalTraj(const EvalTrajOptions& o);

/** What bims-eval masks' command line gives (nullopt: not given). */
struct EvalMasksOptions
{
	std::string gtDir;    ///< labels (ground truth)
	std::string predDir;  ///< predicted masks (bims-run's OUT/masks)
	/** rawlog whose 3D scans give the valid-depth pixels */
	std::optional<std::string> depthValid;
	std::optional<std::string> overlayDir;  ///< default: PRED_MASK_DIR_eval
	bool noPlots = false;                   ///< write no overlays
	std::optional<std::string> json;        ///< the figures as JSON
	double voxelSize = 0.05;  ///< voxel-level figures' cube edge [m] (0: none)
	std::optional<int> movingValue;           ///< label value of moving
	std::optional<int> staticValue;           ///< label value of static
	std::optional<std::string> ignoreValues;  ///< label values not scored
	/** the predictions' stamps when labels are named by time */
	std::optional<std::string> framesCsv;
	double maxDt = 0.01;        ///< largest |t_label - t_prediction| [s]
	bool sparseLabels = false;  ///< labels are a subset of the frames
	/** "run": the labels outside the predictions' span are left out (a
	 * partial run); "labels": every label must have a prediction */
	std::string span = "run";
	std::optional<std::string> strip;  ///< the strip of --strip-frames
	std::string stripFrames;           ///< "i,j,..": scan indices
	bool overwrite = false;  ///< replace an earlier evaluation's overlays
	bool quiet = false;      ///< no per-frame lines, no progress line
	/** the labels' and masks' largest declared size, checked before they
	 * are decoded (--image-max-side, --image-max-pixels) */
	ImageLimits images;
};

/** bims-eval masks: checks the options (UsageError), pairs the labels
 * with the predictions (by index or by time), scores each pair (per frame
 * on stdout unless quiet, the progress line on stderr), writes the
 * overlays, the strip and the JSON, and prints the totals. Returns the
 * exit code (0); errors are thrown. */
int runEvalMasks(const EvalMasksOptions& o);

/** What bims-eval depth-consistency's command line gives. */
struct DepthConsistencyOptions
{
	std::string rawlog;  ///< rawlog with 3D scans
	std::string gt;      ///< poses T_WC (TUM), interpolated at the scans
	int gap = 15;        ///< frames between compared scans
	int step = 4;        ///< pixel subsampling
	int maxFrames = 0;   ///< use only the first N scans (0: all)
};

/** bims-eval depth-consistency: the median depth disagreement of scans
 * \a o.gap frames apart under the poses, and without motion, on stdout.
 * Returns the exit code (0); errors are thrown. */
int runDepthConsistency(const DepthConsistencyOptions& o);

/** What bims-eval attitude's command line gives (nullopt: not given). */
struct EvalAttitudeOptions
{
	std::string ref;                  ///< reference trajectory (TUM)
	std::string est;                  ///< estimated trajectory (TUM)
	std::string refUp = "z";          ///< up axis of the reference's world
	std::string estUp = "z";          ///< up axis of the estimate's world
	double skip_s = 0;                ///< the estimate's first S s left out
	double maxDt = 0.02;              ///< max time difference [s]
	std::optional<std::string> json;  ///< the figures as JSON
};

/** bims-eval attitude: tilt and heading drift of the estimate's rotations
 * against the reference, on stdout, and the JSON. Checks the options
 * (UsageError). Returns the exit code (0); errors are thrown. */
int runEvalAttitude(const EvalAttitudeOptions& o);

}  // namespace bims::apps
