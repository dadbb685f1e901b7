// The viewer's logic without any GUI toolkit (the wx frame in apps/viewer is
// a thin shell over it): replay of a rawlog with a play/pause/step/speed
// clock, the pipeline run while replaying (parameters from an experiment
// .ini, or defaults), or a bims-run output folder shown instead, and the
// content of the 3D view and of the 2D panels.
#pragma once

#include <bims/io/trajectory.h>
#include <bims/pipeline/pipeline.h>
#include <bims/pipeline/stepper.h>
#include <bims/viewer/frame_view.h>
#include <bims/viewer/replay_source.h>

#include <mrpt/img/CImage.h>
#include <mrpt/opengl/COpenGLScene.h>

#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace bims::viewer
{
/** What to open (the viewer's command line). */
struct ViewerOptions
{
	std::string rawlog;      ///< input rawlog (required)
	std::string resultsDir;  ///< bims-run output folder ("" = none)
	std::string configPath;  ///< experiment .ini ("" = built-in defaults)
	/** TUM ground truth; "" = <rawlog without .rawlog>_gt/groundtruth.txt
	 * when that file exists. */
	std::string groundTruth;
	/** Run the pipeline while replaying. Default: on, unless a results
	 * folder is given (then its trajectory and masks are shown). */
	bool runPipeline = true;
	/** Pixel step of the registered cloud (1 = every pixel). */
	int cloudDecimation = 2;
};

class ReplayController
{
 public:
	/** Opens the rawlog (and results folder, config, ground truth); throws
	 * naming the file on any bad input. Nothing is processed yet. */
	explicit ReplayController(const ViewerOptions& opt);
	~ReplayController();

	// --- timeline ---------------------------------------------------------
	size_t frameCount() const { return src_->frameCount(); }
	/** Position of the frame shown in the timeline, -1 before the first
	 * step (its 3D-scan index differs when the input has skipped scans). */
	long currentFrame() const { return cur_; }
	bool atEnd() const { return cur_ + 1 >= static_cast<long>(frameCount()); }
	/** Data time of frame \a i relative to frame 0 [s]. */
	double frameTime(size_t i) const;
	/** Shows the next frame (running the pipeline on it when enabled);
	 * false at the end. */
	bool step();
	/** Shows frame \a i. Going back restarts the replay (the pipeline is
	 * causal) and runs it again up to \a i. */
	void seek(size_t i);

	// --- playback clock ---------------------------------------------------
	void setPlaying(bool on);
	bool playing() const { return playing_; }
	/** Replay speed (1 = real time of the data); clamped to [0.05, 20]. */
	void setSpeed(double s);
	double speed() const { return speed_; }
	/** Advances the play clock by \a wallSeconds and steps the frames due
	 * (at most \a maxSteps; a slow pipeline makes playback lag, not skip).
	 * Stops playing at the end. Returns the number of frames stepped. */
	size_t advance(double wallSeconds, size_t maxSteps = 1);
	/** Wall time until the next frame is due at the play clock [s] (0 when
	 * due; infinity when paused or at the end). */
	double secondsToNextFrame() const;

	// --- content ------------------------------------------------------------
	LayerVisibility& layers() { return layers_; }
	const LayerVisibility& layers() const { return layers_; }
	bool pipelineRunning() const { return pipe_ != nullptr; }
	/** The last pipeline result (null without pipeline or before frame 0). */
	const pipeline::FrameResult* result() const;
	const pipeline::Pipeline* pipelineObj() const { return pipe_.get(); }
	const pipeline::ExperimentConfig& config() const { return cfg_; }
	/** Estimated poses so far (pipeline) or of the results folder. */
	const Trajectory& estimated() const { return est_; }
	/** Ground truth (possibly empty). */
	const Trajectory& groundTruth() const { return gt_; }
	/** The current frame's pose T_WC used to register its cloud: pipeline,
	 * results, ground truth, or identity, in this order. */
	mrpt::poses::CPose3D currentPose() const;

	/** The current frame as the GUI draws it, with the visible layers
	 * (layers()) built. */
	std::shared_ptr<FrameView> view() const;
	/** Replaces the scene's content (main viewport) with view()'s visible
	 * layers. */
	void fillScene(mrpt::opengl::COpenGLScene& scene) const;
	/** A camera looking at the current frame's cloud from behind-above. */
	ViewCamera suggestedCamera() const;
	/** One 2D panel as BGR (CV_8UC3); a grey image when not available. */
	cv::Mat panel(Panel p) const;
	/** All five panels in Panel order (each image converted once). */
	std::array<cv::Mat, kPanelCount> panels() const;
	/** The moving mask shown (pipeline or results folder; may be empty). */
	cv::Mat currentMask() const;
	/** "12 / 149": the position of the current frame and of the last. */
	std::string counterText() const;
	/** One status line: frame, time, pose, moving pixels, timings. */
	std::string statusText() const;

	/** Renders the 3D view offscreen (CFBORender, EGL: works without a
	 * display). */
	mrpt::img::CImage renderOffscreen(const ViewCamera& cam, int width,
	                                  int height) const;

 private:
	void restart();
	void loadResultsFrame();

	ViewerOptions opt_;
	pipeline::ExperimentConfig cfg_;
	std::unique_ptr<ReplaySource> src_;
	std::unique_ptr<pipeline::Pipeline> pipe_;
	std::unique_ptr<pipeline::FrameStepper> stepper_;
	bool srcEnded_ = false;
	long cur_ = -1;
	std::optional<source::SourceFrame> frame_;
	Trajectory est_, gt_, results_;
	cv::Mat resultsMask_;
	LayerVisibility layers_;
	bool playing_ = false;
	double speed_ = 1, clock_ = 0;
};

}  // namespace bims::viewer
