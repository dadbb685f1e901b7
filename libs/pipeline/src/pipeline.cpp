#include <bims/common/clock.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/observed_flow.h>
#include <bims/pipeline/pipeline.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <future>
#include <optional>
#include <stdexcept>

#include "worker.h"

namespace bims::pipeline
{
using Clock = std::chrono::steady_clock;
namespace
{

/** Queues \a job on \a worker; its result (or exception) in the future. */
template <class F>
auto postTask(SerialWorker& worker, F job)
{
	using R = decltype(job());
	auto task = std::make_shared<std::packaged_task<R()>>(std::move(job));
	auto result = task->get_future();
	worker.post([task] { (*task)(); });
	return result;
}

}  // namespace

cv::Mat toMat(const maps::PixelMask& m, cv::Size size)
{
	if (m.width == 0 || m.height == 0) return cv::Mat::zeros(size, CV_8UC1);
	cv::Mat out(m.height, m.width, CV_8UC1);
	std::copy(m.data.begin(), m.data.end(), out.data);
	return out;
}

maps::PixelLabels toPixelLabels(const cv::Mat& labels)
{
	CV_Assert(labels.type() == CV_8SC1 && labels.isContinuous());
	maps::PixelLabels out(labels.cols, labels.rows);
	const auto* p = labels.ptr<int8_t>(0);
	std::copy(p, p + labels.total(), out.label.begin());
	return out;
}

Pipeline::Pipeline(const ExperimentConfig& cfg)
    : cfg_(cfg), odom_(cfg.ego), observed_(cfg.flow), grids_(cfg.grids)
{
	// exclude_moving: the variant's own tier decides what is moving (tier
	// 2 for the flow labels alone, whose voxels tier 2 accumulates).
	grids_.setDecisionTier(
	    maskSource(cfg.pipeline.variant) == MaskSource::Tier1 ? 1 : 2);
	if (cfg.pipeline.flow_thread)
		flowThread_ = std::make_unique<SerialWorker>(1, true, "bims-flow");
	if (cfg.pipeline.cloud_thread)
	{
		cloudThread_ = std::make_unique<SerialWorker>(1, true, "bims-cloud");
		// Tier 0's decay of a frame (the misses) on a thread of its own,
		// during the next frame's egomotion, labels and cloud build (which
		// builds into another buffer and touches no map); the next frame's
		// tiers wait for it.
		decayThread_ = std::make_unique<SerialWorker>(1, true, "bims-decay");
		grids_.setDeferDecay(true);
	}
}

Pipeline::~Pipeline()
{
	if (decaying_.valid()) decaying_.wait();
}

double Pipeline::settleDecay()
{
	return decaying_.valid() ? decaying_.get() : 0;
}

void Pipeline::addImu(const mrpt::obs::CObservationIMU& imu)
{
	odom_.addImu(imu);
}

void Pipeline::addImu(const sensors::ImuSample& s)
{
	odom_.addImu(s);
}

Pipeline::Observed Pipeline::observe(const cv::Mat& prevGrey,
                                     const cv::Mat& curGrey,
                                     const mrpt::img::TCamera& cam,
                                     const Eigen::Matrix3d& R_derot)
{
	const auto t = Clock::now();
	Observed o;
	o.flow = cfg_.flow.derotate
	             ? observed_.computeDerotated(
	                   prevGrey, curGrey,
	                   flow::rotationHomography(
	                       cam, ego::toPose(R_derot, Eigen::Vector3d::Zero())))
	             : observed_.compute(prevGrey, curGrey);
	// a header of the tensor: the next compute() writes only a tensor that
	// nobody else holds (ObservedFlow::tensor())
	o.tensor = observed_.tensor();
	o.ms = msSince(t);
	return o;
}

std::string frameSizeProblem(const ExperimentConfig& cfg, int width, int height,
                             bool hasImage)
{
	const std::string size =
	    std::to_string(width) + "x" + std::to_string(height);
	if (width < 1 || height < 1) return size + ": an empty image";
	const auto& anchor = cfg.ego.anchor;
	if (anchor.enable)
	{
		const int least = 1 << anchor.coarsest_level;
		if (width < least || height < least)
			return size +
			       " is too small for the keyframe alignment, whose "
			       "pyramid halves it [anchor] coarsest_level = " +
			       std::to_string(anchor.coarsest_level) +
			       " times: it needs at least " + std::to_string(least) +
			       " pixels per side";
	}
	if (hasImage) return flow::observedFlowSizeProblem(cfg.flow, width, height);
	return {};
}

double farthestDepthUsed(const ExperimentConfig& cfg)
{
	return std::max({cfg.grids.max_range, cfg.ego.translation.max_depth_m,
	                 cfg.ego.anchor.max_depth_m, cfg.flow.max_depth_m});
}

std::string Pipeline::frameSizeProblem(int width, int height,
                                       bool hasImage) const
{
	if (std::string why =
	        pipeline::frameSizeProblem(cfg_, width, height, hasImage);
	    !why.empty())
		return why;
	if (havePrev_ && prev_.size() != cv::Size(width, height))
		return std::to_string(width) + "x" + std::to_string(height) +
		       " differs from the previous frames' " +
		       std::to_string(prev_.size().width) + "x" +
		       std::to_string(prev_.size().height) +
		       ": one pipeline takes one image size (a new one for another "
		       "camera mode)";
	return {};
}

std::string Pipeline::decode(const FrameInput& in, ego::RgbdFrame& out) const
{
	if (in.scan)
	{
		std::string why = ego::rgbdFrameFrom(*in.scan, cfg_.ego.camera, out);
		if (why.empty())
			if (const std::string small = frameSizeProblem(
			        out.depth.cols, out.depth.rows, out.hasImage());
			    !small.empty())
				why = "depth image " + small;
		return why;
	}
	if (!in.frame) return "no frame";
	const ego::RgbdFrame& f = *in.frame;
	const cv::Size size = f.depth.size();
	if (f.depth.empty() || f.depth.type() != CV_32FC1)
		return "the depth is not a CV_32FC1 image";
	if (f.raw.type() != CV_16UC1 || f.raw.size() != size)
		return "the raw depth is not a CV_16UC1 image of the depth's size";
	if (!f.grey.empty() && (f.grey.type() != CV_8UC1 || f.grey.size() != size))
		return "the image is not a CV_8UC1 image of the depth's size";
	if (const std::string small =
	        frameSizeProblem(size.width, size.height, f.hasImage());
	    !small.empty())
		return "depth image " + small;
	out = f;  // headers: the frame's images are shared, not copied
	return {};
}

bool Pipeline::Lookahead::holds(size_t i, size_t frames) const
{
	return index == i && after + 1 == frames && observed.valid();
}

void Pipeline::Lookahead::drop()
{
	if (observed.valid()) observed.wait();
	observed = {};
	index = kNone;
}

void Pipeline::startLookahead(const Next& next)
{
	ahead_.drop();
	if ((!next.scan && !next.frame) || !flowThread_ ||
	    !cfg_.pipeline.flow_lookahead)
		return;
	const auto t = Clock::now();
	// A frame that cannot be decoded, or that the next call would not pair
	// with this one, is left to that call (which reports it).
	ego::RgbdFrame& f = ahead_.frame;
	if (!decode(next, f).empty() || !f.hasImage() || !cur_.hasImage() ||
	    f.size() != cur_.size() || !(f.t > cur_.t))
		return;
	ahead_.inputMs = msSince(t);
	// What the next call would predict at its start: the egomotion of this
	// frame is final, and the caller has added the IMU samples already.
	const Eigen::Matrix3d R = odom_.predictRotation(f.t);
	ahead_.observed = postTask(
	    *flowThread_,
	    [this, prevGrey = cur_.grey, curGrey = f.grey, cam = f.camera(), R]
	    { return observe(prevGrey, curGrey, cam, R); });
	ahead_.index = next.index;
	ahead_.after = nFrames_;
}

/** A frame's jobs on the two threads, or in sequence: the observed flow
 * (started by the previous frame's look-ahead, posted to the flow thread,
 * or run here when asked for) and the FrameCloud (posted to the cloud
 * thread, or built here). The jobs use the pipeline's members and the
 * frame's result: leaving (also by an exception) waits for them. */
struct Pipeline::FrameJobs
{
	std::future<Observed> observing;
	std::function<Observed()> observeHere;
	std::future<void> building;
	std::function<void()> buildHere;

	~FrameJobs()
	{
		if (observing.valid()) observing.wait();
		if (building.valid()) building.wait();
	}
	/** The observed flow (get() rethrows what the flow job threw). */
	Observed observed()
	{
		return observing.valid() ? observing.get() : observeHere();
	}
	/** The FrameCloud built (get() rethrows what the build threw). */
	void built()
	{
		if (building.valid())
			building.get();
		else
			buildHere();
	}
};

const FrameResult& Pipeline::processFrame(
    const mrpt::obs::CObservation3DRangeScan& scan, size_t index, Next next)
{
	FrameInput in;
	in.scan = &scan;
	in.index = index;
	return processFrame(in, next);
}

const FrameResult& Pipeline::processFrame(const ego::RgbdFrame& frame,
                                          size_t index, Next next)
{
	FrameInput in;
	in.frame = &frame;
	in.index = index;
	return processFrame(in, next);
}

const FrameResult& Pipeline::processFrame(const FrameInput& in, Next next)
{
	const auto t0 = Clock::now();
	FrameResult r;
	r.index = in.index;
	FrameJobs jobs;
	takeInput(in, r, jobs);
	// The flow tier needs an image in both frames: without (depth only) it
	// is off for the frame, and tier 1 decides (tier 2 = tier 1).
	r.flowOff = !cur_.hasImage() || (havePrev_ && !prev_.hasImage());
	const bool haveFlow =
	    havePrev_ && !r.flowOff && prev_.size() == cur_.size();
	if (haveFlow && !jobs.observing.valid()) startObservedFlow(jobs);
	egomotion(r);
	// A refinement may still correct the egomotion (and so the next
	// prediction and the pose the cloud is registered with): then the look
	// ahead and the cloud start after it.
	const bool mayCorrect = cfg_.flow.refine_pose != flow::RefinePose::None &&
	                        cfg_.flow.refine_to_ego;
	if (!mayCorrect) startNextJobs(next, r, jobs);
	maps::PixelLabels labels;
	flowLabels(haveFlow ? &jobs : nullptr, r, labels);
	if (mayCorrect) startNextJobs(next, r, jobs);
	runGrids(haveFlow ? &labels : nullptr, r, jobs);
	finishFrame(r);
	r.ms.total = msSince(t0);
	res_ = std::move(r);
	return res_;
}

void Pipeline::takeInput(const FrameInput& in, FrameResult& r, FrameJobs& jobs)
{
	// The frame decoded by the previous call's look ahead, with its observed
	// flow on the way (only if the frame that queued it completed: prev_ is
	// its frame), or decoded here: grey image, metric depth and camera
	// model, once for all stages.
	if (havePrev_ && ahead_.holds(r.index, nFrames_))
	{
		std::swap(cur_, ahead_.frame);
		jobs.observing = std::move(ahead_.observed);
		ahead_.index = Lookahead::kNone;
		r.flowAhead = true;
		r.ms.input = ahead_.inputMs;
	}
	else
	{
		const auto t = Clock::now();
		ahead_.drop();
		const std::string why = decode(in, cur_);
		if (!why.empty())
			throw std::runtime_error(
			    "3D scan #" + std::to_string(r.index) + " ('" +
			    (in.scan ? in.scan->sensorLabel : std::string("frame")) +
			    "'): " + why);
		r.ms.input = msSince(t);
	}
	r.t = cur_.t;
}

void Pipeline::startObservedFlow(FrameJobs& jobs)
{
	// The observed flow needs only the two images and the rotation it is
	// derotated with, predicted first (gyro) so that it does not depend on
	// the tracker: with flow_thread it runs on the flow thread while the
	// egomotion runs here. Nothing writes the images meanwhile; the result
	// is the same as in sequence.
	const Eigen::Matrix3d R_derot = odom_.predictRotation(cur_.t);
	auto job = [this, prevGrey = prev_.grey, curGrey = cur_.grey,
	            cam = cur_.camera(), R_derot]
	{ return observe(prevGrey, curGrey, cam, R_derot); };
	if (flowThread_)
		jobs.observing = postTask(*flowThread_, job);
	else
		jobs.observeHere = job;
}

void Pipeline::egomotion(FrameResult& r)
{
	// with the previous moving mask keeping features off movers
	const auto t = Clock::now();
	const cv::Mat* fb = (cfg_.pipeline.feedback_mask && !feedback_.empty())
	                        ? &feedback_
	                        : nullptr;
	r.ego = odom_.processFrame(cur_, fb);
	r.T_WC = r.ego.T_WC;
	r.T_CprevC = r.ego.T_CprevC;
	r.ms.egomotion = msSince(t);
}

void Pipeline::startNextJobs(const Next& next, FrameResult& r, FrameJobs& jobs)
{
	startLookahead(next);
	// The cloud: this frame's depth with its camera model at its final pose
	// (its build touches nothing the labels use).
	const sensors::PinholeCamera K = cur_.pinhole();
	jobs.buildHere =
	    [this, depth = cur_.rawDepth(), K, T_WC = r.T_WC, &ms = r.ms.gridsCloud]
	{
		const auto t = Clock::now();
		grids_.buildFrame(depth, K, T_WC);
		ms = msSince(t);
	};
	if (cloudThread_) jobs.building = postTask(*cloudThread_, jobs.buildHere);
}

void Pipeline::flowLabels(FrameJobs* jobs, FrameResult& r,
                          maps::PixelLabels& labels)
{
	// Flow labels on the current frame's pixels (none on the first frame).
	const auto t = Clock::now();
	r.maskFlow = cv::Mat::zeros(cur_.size(), CV_8UC1);
	if (jobs)
	{
		const Observed o = jobs->observed();
		r.ms.flowObserved = o.ms;
		const cv::Mat& obs = o.flow;
		const auto cam = cur_.camera();
		if (cfg_.flow.refine_pose != flow::RefinePose::None)
			commitMotion(
			    flow::refinePoseWithFlow(obs, cur_.depth, cam, r.T_CprevC,
			                             flow::flowPoseParamsFrom(cfg_.flow),
			                             nullptr, &o.tensor),
			    r);
		const cv::Mat exp =
		    flow::expectedFlow(cfg_.flow.expected, cur_.depth, cam, r.T_CprevC);
		r.labels = flow::labelConsistency(obs, exp, cur_.depth, cam, r.T_CprevC,
		                                  cfg_.flow, &r.labelStats, &o.tensor);
		r.maskFlow.setTo(255, r.labels == static_cast<int8_t>(flow::kDiff));
		r.flowObserved = obs;
		r.flowExpected = exp;
		labels = toPixelLabels(r.labels);
	}
	r.ms.flow = msSince(t);
}

void Pipeline::commitMotion(const flow::FlowPoseResult& proposed,
                            FrameResult& r)
{
	// The flow proposes, the pipeline decides: an accepted refinement is the
	// frame's motion, and with refine_to_ego the odometry's last motion too
	// (so its next prediction and the cloud's pose follow it).
	r.flowPose = proposed;
	if (!proposed.ok) return;
	r.T_CprevC = proposed.T_CprevC;
	if (cfg_.flow.refine_to_ego) r.T_WC = odom_.correctLastMotion(r.T_CprevC);
}

void Pipeline::runGrids(const maps::PixelLabels* labels, FrameResult& r,
                        FrameJobs& jobs)
{
	// The three tiers, then the variant's mask.
	const auto t = Clock::now();
	r.ms.gridsDecay = settleDecay();
	jobs.built();
	if (cfg_.pipeline.hold_unregistered && !r.ego.registered())
	{
		// The frame's cloud stays out of the grids; the tracker keeps the
		// last mask fed back (what moved is likely still there).
		r.held = true;
		r.maskTier1 = cv::Mat::zeros(cur_.size(), CV_8UC1);
		r.maskTier2 = cv::Mat::zeros(cur_.size(), CV_8UC1);
		r.mask = cv::Mat::zeros(cur_.size(), CV_8UC1);
		r.ms.grids = msSince(t);
		return;
	}
	const auto& g = grids_.processBuiltFrame(labels, r.flowOff);
	const cv::Size size = cur_.size();
	r.maskTier1 = toMat(g.maskTier1(), size);
	r.maskTier2 = toMat(g.maskTier2(), size);
	r.hitVoxels = g.hitVoxels;
	r.cloudStats = g.stats;
	switch (maskSource(cfg_.pipeline.variant))
	{
		case MaskSource::Tier1:
			r.mask = r.maskTier1;
			r.movingVoxels = g.movingTier1;
			break;
		case MaskSource::Tier2:
			r.mask = r.maskTier2;
			r.movingVoxels = g.movingTier2;
			break;
		case MaskSource::FlowLabels:
			r.mask = r.maskFlow;
			r.movingVoxels = 0;
			break;
	}
	if (const auto* m = maskGrid()) r.movingVoxelCentres = m->movingCells();
	// The tracker of the next frame keeps its features off the tier's own
	// decision: the fill is for the output (a filled false alarm fed back
	// would take a whole static surface from the tracker).
	feedback_ = r.mask;
	const auto fill = cfg_.pipeline.surface_fill;
	if (fill == SurfaceFill::Always ||
	    (fill == SurfaceFill::DepthOnly && r.flowOff))
	{
		r.mask = r.mask.clone();  // the tier's own mask stays as it was
		// Up in the camera's axes from the IMU's attitude, once it has
		// converged (gravity; no heading needed).
		std::optional<Eigen::Vector3d> up;
		if (!odom_.attitude().converging(cur_.t))
			if (const auto R_WC = odom_.imuRotation(cur_.t))
				up = R_WC->transpose() * Eigen::Vector3d::UnitZ();
		r.surfaceFill =
		    fillMovingSurfaces(cur_.depth, cur_.K, r.mask,
		                       cfg_.pipeline.surface, up ? &*up : nullptr);
	}
	r.ms.grids = msSince(t);
	// The decay last: nothing above reads tier 0 (setDeferDecay).
	if (grids_.decayPending())
		decaying_ = postTask(*decayThread_,
		                     [this]
		                     {
			                     const auto t = Clock::now();
			                     grids_.applyPendingDecay();
			                     return msSince(t);
		                     });
}

void Pipeline::finishFrame(FrameResult& r)
{
	r.warmup = nFrames_ < static_cast<size_t>(cfg_.pipeline.warmup_frames);
	if (r.warmup)
	{
		r.mask = cv::Mat::zeros(cur_.size(), CV_8UC1);
		r.movingVoxelCentres.clear();
		r.movingVoxels = 0;
		r.surfaceFill = {};
		feedback_ = r.mask;
	}
	std::swap(prev_, cur_);
	havePrev_ = true;
	++nFrames_;
}

const maps::CMotionGridBase* Pipeline::maskGrid() const
{
	switch (maskSource(cfg_.pipeline.variant))
	{
		case MaskSource::Tier1:
			return grids_.background().get();
		case MaskSource::Tier2:
			return grids_.flowConsistency().get();
		case MaskSource::FlowLabels:
			break;  // the flow labels alone: no grid says moving
	}
	return nullptr;
}

}  // namespace bims::pipeline
