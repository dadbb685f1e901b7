// A whole run over rawlog files: reading, IMU/camera ordering, the frame
// range, the outputs of bims-run and the summary: the batch way to run
// (bims-run's command, bims/apps/run_command.h; bims-flow-check; bims-sweep's
// runs through bims-run).
#pragma once

#include <bims/common/progress.h>
#include <bims/common/stats.h>
#include <bims/io/output_paths.h>
#include <bims/pipeline/pipeline.h>
#include <bims/source/frame_source.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace bims::pipeline
{
/** Inclusive range of 3D-scan indices ("A:B", "A:" or ":B"). */
using source::FrameRange;

/** The check of a --frames range against the inputs (one home:
 * bims/source/frame_source.h). */
using source::checkFrameRangeInInputs;

/** Median and 95th percentile of a series (bims/common/stats.h). */
using bims::Percentiles;

/** What a run measured; what the input held and what of it was skipped is
 * the frame source's (source::FrameOrderStats). */
struct RunSummary : source::FrameOrderStats
{
	size_t framesProcessed = 0;
	size_t framesFlagged = 0;  ///< frames with an egomotion flag
	/** Frames whose motion was not measured, the pose predicted instead
	 * (ego::FrameEgomotion::ok() false; the first frame, the reference,
	 * aside). A flag alone (anchored, new_keyframe, ...) is no failure. */
	size_t framesNotMeasured = 0;
	/** Frames per egomotion flag by name (ego::flagNames; first_frame not
	 * counted). */
	std::map<std::string, size_t> framesFlaggedBy;
	/** What the user should know about how the run went, one sentence
	 * each (e.g. no IMU in the input and the mode it fell back to). */
	std::vector<std::string> notes;
	/** frames whose observed flow ran during the previous frame's grids
	 * ([pipeline] flow_lookahead) */
	size_t framesFlowAhead = 0;
	/** frames without a flow tier (no image in them or in the frame
	 * before: depth only; FrameResult::flowOff) */
	size_t framesWithoutFlow = 0;
	/** frames whose mask the surface fill added to ([pipeline]
	 * surface_fill), and the pixels it added over the run */
	size_t framesSurfaceFilled = 0;
	size_t pixelsSurfaceFilled = 0;
	/** frames held out of the grids (FrameResult::held) */
	size_t framesHeld = 0;
	/** frames flagged imu_missing or imu_gap: no IMU data for their
	 * interval */
	size_t framesWithoutImu = 0;
	/** The input held IMU samples with the label but the run could mostly
	 * not use them (imuMostlyUnusable): status "imu_unusable". */
	bool imuUnusable = false;
	/** Wall time of the whole run: reading, every frame, every output
	 * (static map included; metrics.json excepted). */
	double seconds = 0;
	double cpuSeconds = 0;  ///< CPU time of the process over the run
	/** Peak resident memory of the process at the end of the run [MiB]. */
	double peakResidentMiB = 0;
	double dataSeconds = 0;  ///< time span of the processed frames
	/** Per stage [ms]: the pipeline's input, egomotion, flow, grids, total
	 * (wall); read (reading and decoding the observations up to the frame,
	 * on the reading thread), outputs (writing the frame, on the writing
	 * thread); *_cpu: CPU time of the same (total_cpu: the run's thread
	 * only, not OpenCV's workers); wait_input / wait_output: the run
	 * blocked on the reader / on a full write queue. */
	std::map<std::string, Percentiles> stageMs;
	double meanMovingPixelFraction = 0;  ///< over labelled-depth pixels
	size_t staticMapVoxels = 0;
	std::string variant;
	/** Error that stopped the run early (outputs so far stay valid). */
	std::string error;
	/** Stopped on request (RunOptions::stop) before the end of the input. */
	bool interrupted = false;
	/** "interrupted", "error", "imu_unusable" or "ok" (metrics.json's
	 * "status", in that order of precedence). */
	const char* status() const
	{
		return interrupted      ? "interrupted"
		       : !error.empty() ? "error"
		       : imuUnusable    ? "imu_unusable"
		                        : "ok";
	}
	double fps() const { return seconds > 0 ? framesProcessed / seconds : 0; }
};

/** The rule of status "imu_unusable": the input held IMU samples with the
 * label (imuRead > 0) and more than half of them were skipped
 * (source::imuMostlySkipped) or more than half of the processed frames had
 * no IMU data (framesWithoutImu: imu_missing or imu_gap). */
bool imuMostlyUnusable(const RunSummary& s);

/** Called after each processed frame (e.g. a viewer), on the run's thread,
 * before the frame is queued for writing (the scan's pixelLabels are still
 * the input's). */
using FrameCallback = std::function<void(
    const FrameResult&, const mrpt::obs::CObservation3DRangeScan&)>;

struct RunOptions
{
	std::vector<std::string> rawlogs;
	std::string outDir;  ///< empty: write nothing
	FrameRange frames;
	/** The frames processed of the range's or, without a bounded range,
	 * of an estimate from the share of the input read; each report's note
	 * "frame N" (the scan index). Empty: none. */
	ProgressCallback progress;
	FrameCallback onFrame;
	/** When it turns true (e.g. the programs' stop signals), the run stops
	 * after the current frame: the frames done are written in full,
	 * metrics.json says "status": "interrupted". */
	const std::atomic<bool>* stop = nullptr;
	/** Files the program writes into outDir after the run (bims-run's
	 * report.md): listed in the folder's manifest with the run's own, so
	 * that --overwrite removes them too. */
	std::vector<std::string> laterFiles;
};

/** Throws std::runtime_error naming the frame (scan index and time) if
 * anything bims-run writes of it is not finite: the pose, the moving
 * voxels. */
void checkFiniteOutputs(const FrameResult& r);

/** metrics.json's stages (its stage_ms keys; RunSummary::stageMs). */
const std::vector<std::string>& stageNames();

/** Every number runExperiment writes into metrics.json, by its path as
 * bims-sweep reads it ("fps", "frames_flagged_by.imu_gap",
 * "stage_ms.total.median"): the names a run's metric can have, from the
 * one list of metrics.json's fields. */
std::vector<std::string> metricNames();

/** What runExperiment writes into RunOptions::outDir (bims-run's output
 * folder), for bims::prepareOutputFolder: the files refused as an earlier
 * run's and cleared by --overwrite. */
const OutputFolderLayout& runOutputLayout();

class OutputWriter;

/** What bims-run does with the frames that ran, whatever their source: the
 * run's statistics, its outputs into RunOptions::outDir (when set:
 * effective.ini at once, then each frame's files as it comes) and, at the
 * end, the summary with its notes and metrics.json. One home for the batch
 * run (runExperiment) and the live ROS 2 node (bims-ros2 -o). */
class RunRecorder
{
 public:
	/** Starts the run's clocks; opens the output folder when \a opt.outDir
	 * is set (uses its outDir and laterFiles only). */
	RunRecorder(const ExperimentConfig& cfg, const RunOptions& opt);
	~RunRecorder();
	RunRecorder(const RunRecorder&) = delete;
	RunRecorder& operator=(const RunRecorder&) = delete;

	/** A frame that ran: its statistics, then RunOptions::onFrame, then its
	 * outputs (the IMU observations of \a f.before first; the writer then
	 * owns \a f.scan). \a cpuMs: the frame's CPU time
	 * (FrameStepper::lastCpuMs). Throws as checkFiniteOutputs does, and the
	 * error of an earlier write. */
	void frame(const source::SourceFrame& f, const FrameResult& r, double cpuMs,
	           const FrameCallback& onFrame = {});
	/** Observations after the last frame (FrameOrder::takeTrailing), for
	 * the labelled rawlog. */
	void trailing(const std::vector<mrpt::obs::CObservation::Ptr>& obs);
	/** The summary so far (the frames' counts). */
	const RunSummary& summary() const { return sum_; }
	/** Ends the run: the input's \a stats and \a error (empty: none), every
	 * output closed (the static map of \a pipe), the notes, the timings and
	 * metrics.json; returns the summary. Call once. */
	RunSummary finish(Pipeline& pipe, const source::FrameOrderStats& stats,
	                  const std::string& error, bool interrupted);

 private:
	void addNotes();

	std::string imuLabel_;
	ego::OdometryMode odometryMode_;
	std::unique_ptr<OutputWriter> out_;
	RunSummary sum_;
	std::map<std::string, std::vector<double>> stage_;
	double firstT_, lastT_, movingFracSum_ = 0;
	std::chrono::steady_clock::time_point wall0_;
	double cpu0_;
};

/** Runs \a cfg over the rawlogs, reading ahead on a thread ([pipeline]
 * read_ahead) and writing on another ([output] writer_thread); returns when
 * every output is complete. Writes into outDir (when set):
 * trajectory.txt, masks/NNNNNN.png, moving_voxels/NNNNNN.ply,
 * static_map.{ply,bt}, segmented.rawlog, metrics.json, frames.csv.
 * Bad input (truncated rawlog, missing images) stops the run with
 * summary.error set; everything written so far stays valid. */
RunSummary runExperiment(const ExperimentConfig& cfg, const RunOptions& opt);

/** The summary as an aligned text table. */
std::string formatSummary(const RunSummary& s);

}  // namespace bims::pipeline
