#include <bims/common/frames.h>
#include <bims/flow/expected_flow.h>
#include <bims/pipeline/pipeline.h>

#include <chrono>
#include <future>
#include <stdexcept>

#include "worker.h"

namespace bims::pipeline
{
namespace
{
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0)
{
	return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

mrpt::img::TCamera cameraOf(const ego::RgbdFrame& f)
{
	mrpt::img::TCamera c;
	c.ncols = static_cast<uint32_t>(f.grey.cols);
	c.nrows = static_cast<uint32_t>(f.grey.rows);
	c.setIntrinsicParamsFromValues(f.K(0, 0), f.K(1, 1), f.K(0, 2), f.K(1, 2));
	return c;
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
	// exclude_moving: the variant's own tier decides what is moving.
	grids_.setDecisionTier(cfg.pipeline.variant == Variant::BottomOnly ? 1 : 2);
	if (cfg.pipeline.flow_thread)
		flowThread_ = std::make_unique<SerialWorker>(1, true, "bims-flow");
}

Pipeline::~Pipeline() = default;

void Pipeline::addImu(const mrpt::obs::CObservationIMU& imu)
{
	odom_.addImu(imu);
}

const FrameResult& Pipeline::processFrame(
    const mrpt::obs::CObservation3DRangeScan& scan, size_t index)
{
	const auto t0 = Clock::now();
	FrameResult r;
	r.index = index;

	// Input: grey image + metric depth + intrinsics, once for all stages.
	auto t = Clock::now();
	const std::string why = ego::rgbdFrameFrom(scan, cfg_.ego.camera, cur_);
	if (!why.empty())
		throw std::runtime_error("3D scan #" + std::to_string(index) + " ('" +
		                         scan.sensorLabel + "'): " + why);
	r.t = cur_.t;
	r.ms.input = msSince(t);

	// The rotation the observed flow is derotated with is predicted first
	// (gyro), so that the flow does not depend on the tracker.
	const Eigen::Matrix3d R_derot = odom_.predictRotation(cur_.t);
	const auto cam = cameraOf(cur_);

	// The observed flow needs only the two images (and that prediction):
	// with flow_thread it runs on the flow thread while the egomotion runs
	// here. Nothing touches the images (nor observed_) meanwhile; the result
	// is the same as in sequence.
	const cv::Size size = cur_.grey.size();
	const bool haveFlow = havePrev_ && prev_.grey.size() == size;
	auto observe = [this, &r, &R_derot, &cam]
	{
		const auto t = Clock::now();
		cv::Mat f =
		    cfg_.flow.derotate
		        ? observed_.computeDerotated(
		              prev_.grey, cur_.grey,
		              flow::rotationHomography(
		                  cam, ego::toPose(R_derot, Eigen::Vector3d::Zero())))
		        : observed_.compute(prev_.grey, cur_.grey);
		r.ms.observed = msSince(t);
		return f;
	};
	std::future<cv::Mat> observing;
	// the flow job uses this frame's locals: never leave before it ends
	struct WaitFor
	{
		std::future<cv::Mat>& f;
		~WaitFor()
		{
			if (f.valid()) f.wait();
		}
	} waitForObserving{observing};
	if (haveFlow && flowThread_)
	{
		auto job = std::make_shared<std::packaged_task<cv::Mat()>>(observe);
		observing = job->get_future();
		flowThread_->post([job] { (*job)(); });
	}

	// Egomotion, with the previous moving mask keeping features off movers.
	t = Clock::now();
	const cv::Mat* fb = (cfg_.pipeline.feedback_mask && !feedback_.empty())
	                        ? &feedback_
	                        : nullptr;
	r.ego = odom_.processFrame(cur_, fb);
	r.T_WC = r.ego.T_WC;
	r.T_CprevC = r.ego.T_CprevC;
	r.ms.ego = msSince(t);

	// Flow labels on the current frame's pixels.
	t = Clock::now();
	r.maskFlow = cv::Mat::zeros(size, CV_8UC1);
	maps::PixelLabels pixLabels;
	if (haveFlow)
	{
		// (get() rethrows what the flow job threw)
		const cv::Mat obs = observing.valid() ? observing.get() : observe();
		if (cfg_.flow.refine_pose != "none")
		{
			r.flowPose =
			    flow::refinePoseWithFlow(obs, cur_.depth, cam, r.T_CprevC,
			                             flow::flowPoseParamsFrom(cfg_.flow),
			                             nullptr, &observed_.tensor());
			if (r.flowPose.ok)
			{
				r.T_CprevC = r.flowPose.T_prev_cur;
				if (cfg_.flow.refine_to_ego)
					r.T_WC = odom_.correctLastMotion(r.T_CprevC);
			}
		}
		const cv::Mat exp =
		    cfg_.flow.expected == "linear"
		        ? flow::expectedFlowLinear(cur_.depth, cam, r.T_CprevC)
		        : flow::expectedFlowExact(cur_.depth, cam, r.T_CprevC);
		r.labels = flow::labelConsistency(obs, exp, cur_.depth, cam, r.T_CprevC,
		                                  cfg_.flow, &r.labelStats,
		                                  &observed_.tensor());
		r.maskFlow.setTo(255, r.labels == static_cast<int8_t>(flow::kDiff));
		r.flowObserved = obs;
		r.flowExpected = exp;
		pixLabels = toPixelLabels(r.labels);
	}
	r.ms.flow = msSince(t);

	// The three tiers. The grids take MRPT's scan frame {S} in {W}.
	t = Clock::now();
	const mrpt::poses::CPose3D T_WS =
	    r.T_WC + (mrpt::poses::CPose3D() - T_SC());
	const auto& g =
	    grids_.processFrame(scan, T_WS, haveFlow ? &pixLabels : nullptr);
	r.maskTier1 = toMat(g.maskTier1, size);
	r.maskTier2 = toMat(g.maskTier2, size);
	r.hitVoxels = g.hitVoxels;
	r.cloudStats = g.stats;
	r.ms.grids = msSince(t);

	switch (cfg_.pipeline.variant)
	{
		case Variant::BottomOnly:
			r.mask = r.maskTier1;
			r.movingVoxels = g.movingTier1;
			r.movingVoxelCentres = grids_.background()->movingCells();
			break;
		case Variant::FlowOnly:
			r.mask = r.maskFlow;
			r.movingVoxels = 0;
			break;
		case Variant::Fused:
		case Variant::FusedRaycast:
			r.mask = r.maskTier2;
			r.movingVoxels = g.movingTier2;
			r.movingVoxelCentres = grids_.flow()->movingCells();
			break;
	}
	r.warmup = nFrames_ < static_cast<size_t>(cfg_.pipeline.warmup_frames);
	if (r.warmup)
	{
		r.mask = cv::Mat::zeros(size, CV_8UC1);
		r.movingVoxelCentres.clear();
		r.movingVoxels = 0;
	}
	feedback_ = r.mask;

	std::swap(prev_, cur_);
	havePrev_ = true;
	++nFrames_;
	r.ms.total = msSince(t0);
	res_ = std::move(r);
	return res_;
}

}  // namespace bims::pipeline
