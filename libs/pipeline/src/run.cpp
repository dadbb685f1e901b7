#include <bims/common/errors.h>
#include <bims/common/imu_check.h>
#include <bims/common/progress.h>
#include <bims/ego/depth_correction.h>
#include <bims/ego/flags.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/maps/export.h>
#include <bims/pipeline/run.h>
#include <bims/pipeline/stepper.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/TPixelLabelInfo.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <fstream>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>

#include <bims/common/cpu_time.h>
#include "outputs.h"

namespace bims::pipeline
{
void checkFiniteOutputs(const FrameResult& r)
{
	const auto M =
	    r.T_WC.getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>();
	bool finite = std::isfinite(r.t);
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 4; j++) finite = finite && std::isfinite(M(i, j));
	char what[160];
	std::snprintf(what, sizeof(what), "3D scan #%zu (t %.6f): ", r.index, r.t);
	if (!finite)
		throw std::runtime_error(what +
		                         std::string("the estimated pose is not "
		                                     "finite; nothing of it written"));
	for (const auto& p : r.movingVoxelCentres)
		if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
			throw std::runtime_error(
			    what + std::string("a moving voxel is not finite; nothing of "
			                       "it written"));
}

namespace
{
/** The frames flagged \a name (its ego flag's name). */
size_t flaggedBy(const RunSummary& s, const char* name)
{
	const auto it = s.framesFlaggedBy.find(name);
	return it == s.framesFlaggedBy.end() ? 0 : it->second;
}

/** cv::setNumThreads(n) for the lifetime of the object (n > 0), then the
 * previous setting again. */
class OpenCvThreads
{
 public:
	explicit OpenCvThreads(int n) : before_(cv::getNumThreads())
	{
		if (n > 0) cv::setNumThreads(n);
		set_ = n > 0;
	}
	~OpenCvThreads()
	{
		if (set_) cv::setNumThreads(before_);
	}
	OpenCvThreads(const OpenCvThreads&) = delete;
	OpenCvThreads& operator=(const OpenCvThreads&) = delete;

 private:
	int before_;
	bool set_ = false;
};

/** The error of a run whose \a rawlogs held no 3D scan with \a label. */
std::string noScansError(const std::vector<std::string>& rawlogs,
                         const std::string& label)
{
	std::string files;
	for (const auto& f : rawlogs) files += (files.empty() ? "" : ", ") + f;
	return files + ": no CObservation3DRangeScan (RGB-D) observation" +
	       (label.empty() ? std::string() : " with label '" + label + "'");
}

void addError(RunSummary& sum, const std::string& e)
{
	if (sum.error.find(e) != std::string::npos) return;  // reported already
	sum.error += (sum.error.empty() ? "" : "; then: ") + e;
}
}  // namespace

RunRecorder::RunRecorder(const ExperimentConfig& cfg, const RunOptions& opt)
    : imuLabel_(cfg.ego.sensors.imu_label),
      odometryMode_(cfg.ego.odometry.mode),
      firstT_(NAN),
      lastT_(NAN),
      wall0_(std::chrono::steady_clock::now()),
      cpu0_(processCpuMs())
{
	sum_.variant = choiceName(cfg.pipeline.variant);
	if (opt.outDir.empty()) return;
	out_ =
	    std::make_unique<OutputWriter>(opt.outDir, cfg.output, opt.laterFiles);
	writeFileAtomically(out_->file("effective.ini"), cfg.effectiveIni());
}

RunRecorder::~RunRecorder() = default;

void RunRecorder::frame(const source::SourceFrame& f, const FrameResult& r,
                        double cpuMs, const FrameCallback& onFrame)
{
	stage_["total_cpu"].push_back(cpuMs);
	checkFiniteOutputs(r);
	uint32_t flags = r.ego.flags;
	if (f.imuRejected) flags |= ego::kFlagImuRejected;
	RunSummary& sum = sum_;
	sum.framesProcessed++;
	if (r.flowAhead) sum.framesFlowAhead++;
	if (r.flowOff) sum.framesWithoutFlow++;
	if (r.held) sum.framesHeld++;
	if (r.surfaceFill.added > 0)
	{
		sum.framesSurfaceFilled++;
		sum.pixelsSurfaceFilled += static_cast<size_t>(r.surfaceFill.added);
	}
	const uint32_t counted =
	    flags & ~static_cast<uint32_t>(ego::kFlagFirstFrame);
	if (counted) sum.framesFlagged++;
	if (!r.ego.ok() && !(flags & ego::kFlagFirstFrame)) sum.framesNotMeasured++;
	for (const char* name : ego::flagNames(counted))
		sum.framesFlaggedBy[name]++;
	if (flags & (ego::kFlagImuMissing | ego::kFlagImuGap))
		sum.framesWithoutImu++;
	auto& st = stage_;
	st["read"].push_back(f.cost.readMs);
	st["read_cpu"].push_back(f.cost.readCpuMs);
	st["wait_input"].push_back(f.cost.waitMs);
	st["input"].push_back(r.ms.input);
	st["egomotion"].push_back(r.ms.egomotion);
	st["flow"].push_back(r.ms.flow);
	if (r.ms.flowObserved > 0) st["flow_observed"].push_back(r.ms.flowObserved);
	st["grids"].push_back(r.ms.grids);
	st["grids_cloud"].push_back(r.ms.gridsCloud);
	if (r.ms.gridsDecay > 0) st["grids_decay"].push_back(r.ms.gridsDecay);
	st["total"].push_back(r.ms.total);
	const double validPx = static_cast<double>(r.cloudStats.valid);
	if (validPx > 0) movingFracSum_ += cv::countNonZero(r.mask) / validPx;
	if (std::isnan(firstT_)) firstT_ = r.t;
	lastT_ = r.t;
	// the callback first: the writer then owns the scan
	if (onFrame) onFrame(r, *f.scan);
	if (!out_) return;
	for (const auto& o : f.before) out_->writeOther(o);
	st["wait_output"].push_back(out_->writeFrame(r, f.scan, flags));
}

void RunRecorder::trailing(const std::vector<mrpt::obs::CObservation::Ptr>& obs)
{
	if (out_)
		for (const auto& o : obs) out_->writeOther(o);
}

RunSummary RunRecorder::finish(Pipeline& pipe,
                               const source::FrameOrderStats& stats,
                               const std::string& error, bool interrupted)
{
	static_cast<source::FrameOrderStats&>(sum_) = stats;
	sum_.error = error;
	sum_.interrupted = interrupted;
	// Every output complete (queued frames, static map) before the clock
	// stops: the frames/s are end to end.
	if (out_)
	{
		try
		{
			sum_.staticMapVoxels = out_->close(pipe);
		}
		catch (const std::exception& e)
		{
			addError(sum_, e.what());
		}
		stage_["outputs"] = out_->frameMs();
		stage_["outputs_cpu"] = out_->frameCpuMs();
	}
	addNotes();
	for (auto& [name, v] : stage_)
	{
		const auto& known = stageNames();
		if (std::find(known.begin(), known.end(), name) == known.end())
			throw std::logic_error("stage " + name +
			                       " is not one of stageNames()");
		sum_.stageMs[name] = Percentiles::of(v);
	}
	sum_.dataSeconds = std::isnan(firstT_) ? 0 : lastT_ - firstT_;
	sum_.meanMovingPixelFraction =
	    sum_.framesProcessed ? movingFracSum_ / sum_.framesProcessed : 0;
	sum_.seconds =
	    std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_)
	        .count();
	sum_.cpuSeconds = 1e-3 * (processCpuMs() - cpu0_);
	sum_.peakResidentMiB = peakResidentMiB();
	if (out_)
	{
		try
		{
			out_->writeMetrics(pipe, sum_);
		}
		catch (const std::exception& e)
		{
			addError(sum_, e.what());  // reported by the caller
		}
	}
	return sum_;
}

void RunRecorder::addNotes()
{
	RunSummary& sum = sum_;
	const std::string& imuLabel = imuLabel_;
	for (auto& n : source::imuNotes(sum, imuLabel))
		sum.notes.push_back(std::move(n));
	sum.imuUnusable = imuMostlyUnusable(sum);
	if (sum.imuUnusable && !source::imuMostlySkipped(sum))
		sum.notes.push_back(
		    "the IMU was mostly unusable: " +
		    std::to_string(sum.framesWithoutImu) + " of " +
		    std::to_string(sum.framesProcessed) +
		    " frames had no IMU data for their interval (imu_missing, "
		    "imu_gap) though the input holds " +
		    std::to_string(sum.imuRead) +
		    " IMU samples: are its stamps on the camera's clock?");
	if (sum.framesProcessed > 0 && sum.imuRead == 0 &&
	    odometryMode_ == ego::OdometryMode::Imu)
		sum.notes.push_back(
		    "no IMU samples in the input" +
		    (imuLabel.empty() ? std::string()
		                      : " with sensor label '" + imuLabel + "'") +
		    ": [odometry] mode=imu fell back to vision on every frame "
		    "(rotation and translation from the tracked 3D features, the "
		    "tracker seeded at constant velocity), each flagged "
		    "imu_missing");
	// the inertial filter's flags, each said once: how many frames, what
	// it means
	const std::pair<const char*, const char*> inertialNotes[] = {
	    {"degenerate",
	     "were degenerate: their depth left directions of the position "
	     "unconstrained (a wall, a corridor, glass; frames.csv "
	     "degenerate_dirs), the inertial prediction carried those"},
	    {"inertial_rejected",
	     "had alignments that disagreed with the IMU's prediction beyond its "
	     "uncertainty and were refused (inertial_rejected): the prediction "
	     "stood"},
	    {"inertial_prior",
	     "had intervals without accelerometer samples (a gap, an IMU that "
	     "stopped, stamps on another clock): constant velocity carried them "
	     "(inertial_prior)"},
	    {"accel_saturated",
	     "had saturated accelerometer samples, left out ([inertial] "
	     "accel_range_ms2)"}};
	for (const auto& [flag, text] : inertialNotes)
		if (const size_t n = flaggedBy(sum, flag))
			sum.notes.push_back(std::to_string(n) + " of " +
			                    std::to_string(sum.framesProcessed) +
			                    " frames " + text);
	if (sum.framesWithoutFlow > 0)
		sum.notes.push_back(
		    std::to_string(sum.framesWithoutFlow) + " of " +
		    std::to_string(sum.framesProcessed) +
		    " frames had no image in them or in the frame before (depth "
		    "only): the flow tier was off for them (tier 1 decided, tier 2 "
		    "equals it) and their egomotion came from the keyframe "
		    "alignment's geometric term alone (flagged no_image)");
	if (sum.framesHeld > 0)
		sum.notes.push_back(
		    std::to_string(sum.framesHeld) + " of " +
		    std::to_string(sum.framesProcessed) +
		    " frames were held out of the grids, their masks empty: their "
		    "pose was not measured against the static scene (lost, or every "
		    "alignment refused by the IMU; frames.csv held, [pipeline] "
		    "hold_unregistered)");
	if (sum.framesSurfaceFilled > 0)
		sum.notes.push_back(
		    "the surface fill ([pipeline] surface_fill) called " +
		    std::to_string(sum.pixelsSurfaceFilled) +
		    " more pixels moving on " +
		    std::to_string(sum.framesSurfaceFilled) +
		    " frames: the rest of depth surfaces the tiers called mostly "
		    "moving (frames.csv filled_px)");
}

RunSummary runExperiment(const ExperimentConfig& cfg, const RunOptions& opt)
{
	if (opt.rawlogs.empty())
		throw std::invalid_argument("no input rawlog given");
	const OpenCvThreads cvThreads(cfg.pipeline.opencv_threads);
	RunRecorder rec(cfg, opt);
	Pipeline pipe(cfg);
	// a bounded range has a known total; otherwise it is estimated from the
	// share of the input read
	const bool bounded = opt.frames.bounded();
	Progress progress;
	progress.total = bounded ? opt.frames.last - opt.frames.first + 1 : 0;
	reportProgress(opt.progress, progress);

	FrameStepper stepper(pipe);
	// after a frame ran: its statistics and outputs
	auto process = [&](const source::SourceFrame& f, const FrameResult& r)
	{
		rec.frame(f, r, stepper.lastCpuMs(), opt.onFrame);
		const size_t done = rec.summary().framesProcessed;
		if (!bounded && f.inputFraction > 0)
		{
			const double scans = (f.index + 1) / f.inputFraction;
			progress.total =
			    std::max(done, static_cast<size_t>(scans + 0.5) -
			                       std::min(opt.frames.first, f.index));
			progress.estimated = true;
		}
		progress.done = done;
		progress.note = "frame " + std::to_string(f.index);
		reportProgress(opt.progress, progress);
	};

	std::string error, readError;  ///< the input's, after the frames before it
	bool interrupted = false;
	source::FrameOrderParams order = source::FrameOrderParams::of(
	    cfg.ego, cfg.pipeline.imu_wait_s, "bims-run");
	order.frames = opt.frames;
	order.keepInput = !opt.outDir.empty();
	std::optional<source::RawlogFrameSource> input;
	source::FrameOrderStats stats;
	try
	{
		input.emplace(opt.rawlogs, order, cfg.pipeline.read_ahead);
		for (bool end = false; !end;)
		{
			if (opt.stop && *opt.stop)
			{
				interrupted = true;  // the frames done stay written
				break;
			}
			auto f = input->next();
			end = !f;
			if (f) stepper.add(std::move(*f));
			while (auto done = stepper.run(end))
				process(done->input, done->result);
		}
		if (!interrupted) rec.trailing(input->takeTrailing());
	}
	catch (const std::exception& e)
	{
		error = withoutBacktrace(e.what());
	}
	if (input)
	{
		readError = input->error();
		stats = input->stats();
	}
	if (!readError.empty())  // first: it came first
		error = readError + (error.empty() ? "" : "; then: " + error);
	if (stats.scansRead == 0 && error.empty())
		error = noScansError(opt.rawlogs, cfg.ego.sensors.rgbd_label);
	progress.finished = true;
	progress.note.clear();
	reportProgress(opt.progress, progress);
	return rec.finish(pipe, stats, error, interrupted);
}

bool imuMostlyUnusable(const RunSummary& s)
{
	return s.imuRead > 0 && (source::imuMostlySkipped(s) ||
	                         2 * s.framesWithoutImu > s.framesProcessed);
}

std::string formatSummary(const RunSummary& s)
{
	std::ostringstream o;
	char buf[256];
	std::snprintf(buf, sizeof(buf),
	              "variant %s: %zu frames (%zu with the motion not measured) "
	              "of %zu 3D scans, %zu IMU samples, %.1f s of data\n",
	              s.variant.c_str(), s.framesProcessed, s.framesNotMeasured,
	              s.scansRead, s.imuRead, s.dataSeconds);
	o << buf;
	if (s.imuUnusable)
		o << "status imu_unusable: the IMU was mostly unusable (see the "
		     "note)\n";
	std::snprintf(buf, sizeof(buf),
	              "wall time %.1f s, %.1f frames/s end to end (CPU %.1f s, all "
	              "threads; peak memory %.0f MiB); mean moving-pixel fraction "
	              "%.2f %%\n",
	              s.seconds, s.fps(), s.cpuSeconds, s.peakResidentMiB,
	              100.0 * s.meanMovingPixelFraction);
	o << buf;
	o << "stage        median ms   p95 ms   mean ms\n";
	for (const auto& k : stageNames())
	{
		const auto it = s.stageMs.find(k);
		if (it == s.stageMs.end()) continue;
		std::snprintf(buf, sizeof(buf), "%-12s %9.2f %8.2f %9.2f\n", k.c_str(),
		              it->second.median, it->second.p95, it->second.mean);
		o << buf;
	}
	if (!s.framesFlaggedBy.empty())
	{
		// most frequent first
		std::vector<std::pair<std::string, size_t>> by(
		    s.framesFlaggedBy.begin(), s.framesFlaggedBy.end());
		std::stable_sort(by.begin(), by.end(),
		                 [](const auto& a, const auto& b)
		                 { return a.second > b.second; });
		o << "frames per egomotion flag:";
		for (size_t k = 0; k < by.size(); ++k)
			o << (k ? ", " : " ") << by[k].first << " " << by[k].second;
		o << " (docs/ego.md)\n";
	}
	for (const auto& note : s.notes) o << "note: " << note << "\n";
	if (s.imuRejected || s.imuOutOfOrder || s.imuBadStamp || s.scansBadStamp ||
	    s.scansOutOfOrder)
	{
		std::snprintf(buf, sizeof(buf),
		              "not used: %zu IMU samples (a field not finite or "
		              "beyond range), %zu IMU samples out of order or "
		              "repeated, %zu with a stray timestamp, %zu 3D scans with "
		              "a stray timestamp, %zu out of order (warnings above)\n",
		              s.imuRejected, s.imuOutOfOrder, s.imuBadStamp,
		              s.scansBadStamp, s.scansOutOfOrder);
		o << buf;
	}
	if (!s.error.empty()) o << "stopped early: " << s.error << "\n";
	return o.str();
}

}  // namespace bims::pipeline
