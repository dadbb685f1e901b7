// One frame, in order (docs/architecture.md, docs/pipeline.md):
//   egomotion (fed the previous frame's mask) -> observed and expected flow
//   -> Diff/notDiff labels -> the frame's voxel cloud -> the grids: tier 0
//   hands out O- -> tier 1 (background subtraction) -> tier 2 (with the flow
//   labels); tier 0 folds the frame in (with exclude_moving after the
//   posteriors, the voxels the decision tier calls static only) -> MAP ->
//   moving voxels and the moving-pixel mask -> the surface fill (output only)
//   -> the tier's mask fed back to the tracker.
// No I/O: the caller feeds observations in time order. Up to four threads
// beside the caller's: the observed flow ([pipeline] flow_thread) runs
// during the egomotion, and, told the next frame (flow_lookahead), that
// frame's observed flow during this frame's grids; the voxel cloud
// (cloud_thread) is built while the labels run; tier 0's decay of a frame
// runs during the next frame until its grids need it.
#pragma once

#include <bims/ego/odometry.h>
#include <bims/flow/consistency.h>
#include <bims/flow/flow_pose.h>
#include <bims/flow/observed_flow.h>
#include <bims/maps/motion_grids.h>
#include <bims/pipeline/config.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <opencv2/core.hpp>

#include <future>
#include <memory>
#include <vector>

namespace bims::pipeline
{
class SerialWorker;

/** Wall time of each stage of one frame [ms]. */
struct StageTimes
{
	// named as metrics.json's stages (RunSummary::stageMs)
	double input = 0;      ///< decoding images, depth conversion
	double egomotion = 0;  ///< tracking + motion estimation
	/** observed + expected flow + labels, on the caller's thread (with
	 * flow_thread: what is left of the observed flow after the egomotion) */
	double flow = 0;
	double flowObserved = 0;  ///< the observed flow alone, on whichever thread
	/** cloud building (or waiting for it) + the tiers + the surface fill */
	double grids = 0;
	double gridsCloud = 0;  ///< building the FrameCloud, on whichever thread
	/** tier 0's decay (frustum, raycast) of the previous frame on the decay
	 * thread (with cloud_thread; else it is part of grids), which this
	 * frame waited for before its grids; 0 if none */
	double gridsDecay = 0;
	double total = 0;
};

/** Everything one frame produced. */
struct FrameResult
{
	size_t index = 0;           ///< 3D-scan index in the input (from 0)
	double t = 0;               ///< camera timestamp [s]
	mrpt::poses::CPose3D T_WC;  ///< estimated camera pose
	/** Relative to the previous frame: the egomotion's, or its refinement
	 * against the dense flow ([flow] refine_pose; then ego.T_CprevC and
	 * ego.T_WC keep the feature-based estimate). */
	mrpt::poses::CPose3D T_CprevC;
	ego::FrameEgomotion ego;        ///< egomotion details (flags, inliers, ...)
	flow::FlowPoseResult flowPose;  ///< the dense-flow refinement, if any
	bool warmup = false;            ///< mask forced empty (warm-up frame)
	/** Not put into the grids, masks empty: its pose was not measured
	 * against the static scene ([pipeline] hold_unregistered). */
	bool held = false;
	/** The flow tier is off for this frame: it or the previous one has no
	 * image (depth only). Tier 1 decides; tier 2 equals it; no labels. */
	bool flowOff = false;
	/** its observed flow ran during the previous frame (flow_lookahead) */
	bool flowAhead = false;
	/** The variant's moving-pixel mask (CV_8UC1, 255 = moving): its tier's
	 * decision, with [pipeline] surface_fill its surfaces filled. */
	cv::Mat mask;
	/** What the surface fill added to the tier's decision. */
	SurfaceFillStats surfaceFill;
	/** The three decisions side by side (CV_8UC1, 255 = moving). */
	cv::Mat maskTier1, maskTier2, maskFlow;
	/** Flow labels (CV_8SC1: -1 none, 0 notDiff, 1 Diff); empty on frame 0. */
	cv::Mat labels;
	/** Observed and expected backward flow on the current frame's pixels
	 * (CV_32FC2 [px], u_{t-1} - u_t, NaN = none; flow/expected_flow.h);
	 * empty on frame 0. For viewers. */
	cv::Mat flowObserved, flowExpected;
	flow::LabelStats labelStats;
	size_t hitVoxels = 0, movingVoxels = 0;
	/** Centres [m, {W}] of the voxels the variant labels moving. */
	std::vector<mrpt::math::TPoint3D> movingVoxelCentres;
	maps::FrameStats cloudStats;
	StageTimes ms;
};

/** A frame for Pipeline::processFrame(): its 3D scan (decoded by the
 * pipeline) or its frame already decoded, and its 3D-scan index. */
struct FrameInput
{
	const mrpt::obs::CObservation3DRangeScan* scan = nullptr;
	const ego::RgbdFrame* frame = nullptr;  ///< used when scan is null
	size_t index = 0;
};
/** The frame after the one Pipeline::processFrame() runs, already at hand. */
using NextFrame = FrameInput;

/** Why a \a width x \a height frame (\a hasImage: with an image, else depth
 * only) cannot run in a pipeline of \a cfg; "" when it can. The keyframe
 * alignment ([anchor] enable) halves the frame [anchor] coarsest_level
 * times: at least 2^coarsest_level pixels per side; the observed flow of a
 * frame with an image: flow::observedFlowSizeProblem. Every other stage
 * takes any size. The one check of a frame's size: Pipeline::processFrame
 * (bims-run, the viewer, bims-grab) and the Python module make it before
 * any stage runs. */
std::string frameSizeProblem(const ExperimentConfig& cfg, int width, int height,
                             bool hasImage);

/** The farthest depth reading [m] a stage of \a cfg uses: the largest of
 * [grids] max_range, [translation] max_depth_m, [anchor] max_depth_m and
 * [flow] max_depth_m. Every stage skips a reading beyond it (only the
 * grids' decay sees such a reading, as free space up to max_range). The
 * Python module takes float depth beyond it as no reading. */
double farthestDepthUsed(const ExperimentConfig& cfg);

class Pipeline
{
 public:
	explicit Pipeline(const ExperimentConfig& cfg);
	~Pipeline();
	Pipeline(const Pipeline&) = delete;
	Pipeline& operator=(const Pipeline&) = delete;

	/** Feeds an IMU observation (label filtered by [sensors] imu_label). */
	void addImu(const mrpt::obs::CObservationIMU& imu);
	/** Feeds an IMU sample already decoded (no label filter). */
	void addImu(const sensors::ImuSample& s);

	using Next = NextFrame;

	/** Runs one RGB-D frame; \a index is its 3D-scan index. Throws
	 * std::runtime_error naming the frame when the observation has no
	 * usable depth image (or an unusable intensity image), or one too small
	 * for the pipeline (frameSizeProblem). A scan without
	 * an intensity image is a depth-only frame: no flow tier
	 * (FrameResult::flowOff), the egomotion without features.
	 *
	 * \a next (optional): the frame the next call will run, given only when
	 * every IMU sample that call would see has been added already (results
	 * are then the same as without it). With flow_thread and flow_lookahead
	 * its observed flow starts on the flow thread during this frame's grids;
	 * the next call takes it if it runs that frame (same index), and drops
	 * it otherwise. The observation must stay alive until that call. */
	const FrameResult& processFrame(
	    const mrpt::obs::CObservation3DRangeScan& scan, size_t index,
	    Next next = {});
	/** The same for a frame decoded by the caller (ego::rgbdFrameFrom: the
	 * same results as its scan). Its images are shared, not copied: the
	 * pipeline reads them until the frame after the next one (the flow
	 * pairs a frame with the one before), so they must not be written
	 * meanwhile. Throws std::runtime_error for images of other types or
	 * sizes. */
	const FrameResult& processFrame(const ego::RgbdFrame& frame, size_t index,
	                                Next next = {});
	const FrameResult& processFrame(const FrameInput& in, Next next = {});

	/** Why this pipeline cannot run a \a width x \a height frame (with an
	 * image or depth only): ::frameSizeProblem() of its config, or a size
	 * other than its previous frames' (one pipeline takes one image size,
	 * as a run: its keyframes, masks and flow are of that size); "" when it
	 * can. processFrame() checks it; a caller may ask first. */
	std::string frameSizeProblem(int width, int height, bool hasImage) const;

	const FrameResult& last() const { return res_; }
	const ExperimentConfig& config() const { return cfg_; }
	/** The grids after the last frame (waits for its decay on the decay
	 * thread; throws what that decay threw). */
	const maps::MotionGrids& grids()
	{
		settleDecay();
		return grids_;
	}
	/** The grids as they are, changing nothing: tiers 1 and 2 after the
	 * last frame; tier 0 (occupancy() const) only once its decay is settled
	 * (the non-const grids(); else std::logic_error). */
	const maps::MotionGrids& grids() const { return grids_; }
	/** The tier whose decision is the variant's mask (tier 1 or 2; nullptr
	 * when the flow labels alone decide, flow-only): the frame's moving
	 * voxels are its, and the static map leaves out what it calls moving. */
	const maps::CMotionGridBase* maskGrid() const;
	const ego::Odometry& odometry() const { return odom_; }
	size_t framesProcessed() const { return nFrames_; }

 private:
	ExperimentConfig cfg_;
	ego::Odometry odom_;
	flow::ObservedFlow observed_;
	maps::MotionGrids grids_;
	ego::RgbdFrame cur_, prev_;
	bool havePrev_ = false;
	cv::Mat feedback_;
	FrameResult res_;
	size_t nFrames_ = 0;
	/** The observed flow of a frame with the structure tensor of its image
	 * (both owned: the flow thread does not touch them afterwards). */
	struct Observed
	{
		cv::Mat flow, tensor;
		double ms = 0;
	};
	Observed observe(const cv::Mat& prevGrey, const cv::Mat& curGrey,
	                 const mrpt::img::TCamera& cam,
	                 const Eigen::Matrix3d& R_derot);
	// The steps of processFrame(), in their order (pipeline.cpp).
	struct FrameJobs;
	/** \a in into \a out; what is wrong, or empty. */
	std::string decode(const FrameInput& in, ego::RgbdFrame& out) const;
	void takeInput(const FrameInput& in, FrameResult& r, FrameJobs& jobs);
	void startObservedFlow(FrameJobs& jobs);
	void egomotion(FrameResult& r);
	/** The next frame's look ahead, and this frame's FrameCloud. */
	void startNextJobs(const Next& next, FrameResult& r, FrameJobs& jobs);
	/** \a jobs null: no previous frame to take the flow from. */
	void flowLabels(FrameJobs* jobs, FrameResult& r, maps::PixelLabels& labels);
	/** The dense flow's proposed motion, committed when it is accepted. */
	void commitMotion(const flow::FlowPoseResult& proposed, FrameResult& r);
	void runGrids(const maps::PixelLabels* labels, FrameResult& r,
	              FrameJobs& jobs);
	void finishFrame(FrameResult& r);

	/** Decodes \a next into ahead_ and queues its observed flow. */
	void startLookahead(const Next& next);

	/** The next frame, decoded ahead, with its observed flow queued on the
	 * flow thread (flow_lookahead). */
	struct Lookahead
	{
		static constexpr size_t kNone = static_cast<size_t>(-1);
		ego::RgbdFrame frame;
		size_t index = kNone;  ///< its 3D-scan index; kNone: nothing queued
		size_t after = 0;      ///< framesProcessed() when it was queued
		double inputMs = 0;    ///< its decoding
		std::future<Observed> observed;
		/** Whether it holds frame \a index, queued by the frame before
		 * (\a frames processed since). */
		bool holds(size_t index, size_t frames) const;
		/** Waits for the queued flow and forgets it. */
		void drop();
	};
	Lookahead ahead_;
	std::unique_ptr<SerialWorker> flowThread_;   ///< null: flow in sequence
	std::unique_ptr<SerialWorker> cloudThread_;  ///< null: cloud in sequence
	/** With cloud_thread: tier 0's decay of a frame, during the next frame
	 * (beside that frame's cloud build). */
	std::unique_ptr<SerialWorker> decayThread_;
	/** The last frame's decay on the decay thread (its result: the decay's
	 * ms); settleDecay() waits for it and returns those ms (0 if none was
	 * in flight). */
	std::future<double> decaying_;
	double settleDecay();
};

/** maps::PixelMask -> CV_8UC1 (a copy; 0x0 mask -> \a size of zeros). */
cv::Mat toMat(const maps::PixelMask& m, cv::Size size);
/** flow labels (CV_8SC1) -> maps::PixelLabels. */
maps::PixelLabels toPixelLabels(const cv::Mat& labels);

}  // namespace bims::pipeline
