#include <bims/common/frames.h>
#include <bims/io/frame_files.h>
#include <bims/io/image_file.h>
#include <bims/viewer/controller.h>
#include <bims/viewer/panels.h>

#include <mrpt/system/filesystem.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

namespace bims::viewer
{
namespace
{
/** The pose of \a traj nearest in time to \a t (traj not empty). */
const StampedPose& nearest(const Trajectory& traj, double t)
{
	auto it = std::lower_bound(traj.begin(), traj.end(), t,
	                           [](const StampedPose& p, double v)
	                           { return p.t < v; });
	if (it == traj.end()) return traj.back();
	if (it != traj.begin() && t - std::prev(it)->t < it->t - t)
		return *std::prev(it);
	return *it;
}

std::string defaultGroundTruth(const std::string& rawlog)
{
	std::string stem = rawlog;
	const std::string ext = ".rawlog";
	if (stem.size() > ext.size() &&
	    stem.compare(stem.size() - ext.size(), ext.size(), ext) == 0)
		stem.resize(stem.size() - ext.size());
	const std::string gt = stem + "_gt/groundtruth.txt";
	return mrpt::system::fileExists(gt) ? gt : std::string();
}
}  // namespace

ReplayController::ReplayController(const ViewerOptions& opt) : opt_(opt)
{
	if (opt_.rawlog.empty()) throw std::invalid_argument("no rawlog given");
	if (!opt_.configPath.empty())
		cfg_.loadFromFile(opt_.configPath);
	else
		cfg_.source = "<defaults>";
	if (opt_.cloudDecimation < 1) opt_.cloudDecimation = 1;

	src_ = std::make_unique<ReplaySource>(
	    opt_.rawlog, source::FrameOrderParams::of(
	                     cfg_.ego, cfg_.pipeline.imu_wait_s, "bims-viewer"));

	if (!opt_.resultsDir.empty())
	{
		const std::string traj = opt_.resultsDir + "/trajectory.txt";
		if (!mrpt::system::fileExists(traj))
			throw std::runtime_error(opt_.resultsDir +
			                         ": not a bims-run output folder (no "
			                         "trajectory.txt)");
		results_ = loadTumTrajectory(traj);
	}
	const std::string gt = opt_.groundTruth.empty()
	                           ? defaultGroundTruth(opt_.rawlog)
	                           : opt_.groundTruth;
	if (!gt.empty()) gt_ = loadTumTrajectory(gt);
	restart();
}

ReplayController::~ReplayController() = default;

void ReplayController::restart()
{
	src_->rewind();
	srcEnded_ = false;
	stepper_.reset();
	pipe_.reset();
	if (opt_.runPipeline)
	{
		pipe_ = std::make_unique<pipeline::Pipeline>(cfg_);
		stepper_ = std::make_unique<pipeline::FrameStepper>(*pipe_);
	}
	est_ = pipe_ ? Trajectory() : results_;
	frame_.reset();
	resultsMask_.release();
	cur_ = -1;
	clock_ = 0;
}

double ReplayController::frameTime(size_t i) const
{
	const auto& t = src_->frameTimes();
	return t.at(i) - t.front();
}

bool ReplayController::step()
{
	std::optional<source::SourceFrame> f;
	if (!stepper_)
		f = src_->next();
	else
	{
		// as bims-run runs them (pipeline::FrameStepper)
		for (;;)
		{
			if (auto done = stepper_->run(srcEnded_))
			{
				est_.push_back({done->input.t, done->result.T_WC});
				f = std::move(done->input);
				break;
			}
			if (srcEnded_) break;
			auto in = src_->next();
			srcEnded_ = !in;
			if (in) stepper_->add(std::move(*in));
		}
	}
	if (!f) return false;
	++cur_;
	frame_ = std::move(f);
	loadResultsFrame();
	return true;
}

void ReplayController::loadResultsFrame()
{
	resultsMask_.release();
	if (opt_.resultsDir.empty() || !frame_) return;
	// bims-run names its files by the 3D-scan index
	const std::string p =
	    opt_.resultsDir + "/masks/" + frameFileName(frame_->index);
	if (mrpt::system::fileExists(p))
		resultsMask_ =
		    readImageFile(p, cv::IMREAD_GRAYSCALE, "mask", cfg_.input);
}

void ReplayController::seek(size_t i)
{
	if (i >= frameCount()) i = frameCount() - 1;
	if (static_cast<long>(i) < cur_) restart();
	while (cur_ < static_cast<long>(i) && step())
	{
	}
	clock_ = frameTime(static_cast<size_t>(std::max(0L, cur_)));
}

void ReplayController::setPlaying(bool on)
{
	if (on && atEnd()) restart();
	playing_ = on;
	clock_ = cur_ >= 0 ? frameTime(static_cast<size_t>(cur_)) : 0;
}

void ReplayController::setSpeed(double s)
{
	speed_ = std::clamp(s, 0.05, 20.0);
}

size_t ReplayController::advance(double wallSeconds, size_t maxSteps)
{
	if (!playing_) return 0;
	clock_ += std::max(0.0, wallSeconds) * speed_;
	size_t n = 0;
	while (n < maxSteps && !atEnd())
	{
		const size_t next = static_cast<size_t>(cur_ + 1);
		if (cur_ >= 0 && frameTime(next) > clock_) break;
		if (!step()) break;
		++n;
	}
	// A slow pipeline makes playback lag; don't let the clock run away.
	if (cur_ >= 0 && clock_ > frameTime(static_cast<size_t>(cur_)) + 0.25)
		clock_ = frameTime(static_cast<size_t>(cur_));
	if (atEnd()) playing_ = false;
	return n;
}

double ReplayController::secondsToNextFrame() const
{
	if (!playing_ || atEnd()) return std::numeric_limits<double>::infinity();
	if (cur_ < 0) return 0;
	const double dt = frameTime(static_cast<size_t>(cur_ + 1)) - clock_;
	return std::max(0.0, dt / speed_);
}

const pipeline::FrameResult* ReplayController::result() const
{
	return (pipe_ && cur_ >= 0) ? &pipe_->last() : nullptr;
}

mrpt::poses::CPose3D ReplayController::currentPose() const
{
	if (const auto* r = result()) return r->T_WC;
	if (frame_ && !results_.empty()) return nearest(results_, frame_->t).T_WC;
	if (frame_ && !gt_.empty()) return nearest(gt_, frame_->t).T_WC;
	return {};
}

cv::Mat ReplayController::currentMask() const
{
	if (const auto* r = result()) return r->mask;
	return resultsMask_;
}

cv::Mat ReplayController::panel(Panel p) const
{
	return panels()[static_cast<size_t>(p)];
}

std::array<cv::Mat, kPanelCount> ReplayController::panels() const
{
	std::array<cv::Mat, kPanelCount> out;
	const auto at = [&](Panel p) -> cv::Mat& { return out[size_t(p)]; };
	if (!frame_)
	{
		for (auto& m : out) m = placeholderPanel({320, 240}, "no frame yet");
		return out;
	}
	// each image converted once for all five panels
	const auto& scan = *frame_->scan;
	const cv::Mat bgr = intensityBgr(scan);
	const cv::Mat depth = depthColour(scan);
	const cv::Size size =
	    bgr.empty() ? cv::Size(static_cast<int>(scan.rangeImage.cols()),
	                           static_cast<int>(scan.rangeImage.rows()))
	                : bgr.size();
	const cv::Mat mask = currentMask();
	if (!bgr.empty())
		at(Panel::RgbMask) = overlayMask(bgr, mask);
	else if (!depth.empty())  // depth only: the mask over the depth in grey
	{
		cv::Mat grey;
		cv::cvtColor(depth, grey, cv::COLOR_BGR2GRAY);
		cv::cvtColor(grey, grey, cv::COLOR_GRAY2BGR);
		at(Panel::RgbMask) = overlayMask(grey, mask);
	}
	else
		at(Panel::RgbMask) = placeholderPanel(size, "no image");
	at(Panel::Depth) =
	    depth.empty() ? placeholderPanel(size, "no valid depth") : depth;

	const auto* r = result();
	// why a flow panel is empty
	const char* noFlow = !r           ? "pipeline off: no flow"
	                     : r->flowOff ? "depth only: flow tier off"
	                                  : "no flow on the first frame";
	if (r && !r->flowObserved.empty())
	{
		// One magnitude scale for both, so that they compare.
		double maxMag = 0;
		for (const cv::Mat* f : {&r->flowObserved, &r->flowExpected})
		{
			if (f->empty()) continue;
			for (int v = 0; v < f->rows; ++v)
				for (int u = 0; u < f->cols; ++u)
				{
					const auto x = f->at<cv::Vec2f>(v, u);
					const double m = std::hypot(x[0], x[1]);
					if (std::isfinite(m)) maxMag = std::max(maxMag, m);
				}
		}
		const double scale = std::max(1.0, 0.5 * maxMag);
		at(Panel::FlowObserved) = flowColour(r->flowObserved, scale, size);
		at(Panel::FlowExpected) = flowColour(r->flowExpected, scale, size);
	}
	else
		at(Panel::FlowObserved) = at(Panel::FlowExpected) =
		    placeholderPanel(size, noFlow);
	at(Panel::Labels) = r && !r->labels.empty()
	                        ? labelsColour(r->labels, bgr)
	                        : placeholderPanel(size, noFlow);
	return out;
}

std::string ReplayController::counterText() const
{
	return std::to_string(cur_) + " / " + std::to_string(frameCount() - 1);
}

std::string ReplayController::statusText() const
{
	std::ostringstream s;
	s.setf(std::ios::fixed);
	s.precision(3);
	if (cur_ < 0)
	{
		s << frameCount() << " frames, " << src_->imuCount() << " IMU samples; "
		  << (pipe_ ? "pipeline on" : "pipeline off");
		return s.str();
	}
	s << "frame " << cur_ << "/" << frameCount() - 1
	  << "  t=" << frameTime(cur_) << " s";
	const auto T = currentPose();
	s.precision(2);
	s << "  pos=(" << T.x() << ", " << T.y() << ", " << T.z() << ")";
	if (const auto* r = result())
	{
		const double valid = static_cast<double>(r->cloudStats.valid);
		const double moving = r->mask.empty() ? 0 : cv::countNonZero(r->mask);
		s.precision(1);
		s << "  moving " << (valid > 0 ? 100.0 * moving / valid : 0.0)
		  << "% px, " << r->movingVoxels << " voxels  [" << r->ms.total
		  << " ms: ego " << r->ms.egomotion << ", flow " << r->ms.flow
		  << ", grids " << r->ms.grids << "]";
	}
	s.precision(2);
	s << "  x" << speed_;
	return s.str();
}

}  // namespace bims::viewer
