#include <bims/source/frame_source.h>

#include <bims/sensors/imu_sample.h>

#include "read_ahead.h"

#include <mrpt/core/Clock.h>
#include <mrpt/core/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace bims::source
{
namespace
{
constexpr double kNever = -std::numeric_limits<double>::infinity();

bool labelMatches(const std::string& want, const std::string& have)
{
	return want.empty() || want == have;
}

std::string quoted(const std::string& label)
{
	return "'" + label + "'";
}

// A stamp more than kMaxScanGapS after the last one used is held until the
// next one decides (3D scans and IMU samples alike).
bool farAhead(double t, double last)
{
	return std::isfinite(last) && t - last > kMaxScanGapS;
}
// The one after a held far stamp follows it within the gap: the recording
// jumped (the held one is used), else its stamp was stray.
bool followsHeld(double t, double held)
{
	return t > held && t - held <= kMaxScanGapS;
}

void add(InputCost& a, const InputCost& b)
{
	a.readMs += b.readMs;
	a.readCpuMs += b.readCpuMs;
	a.waitMs += b.waitMs;
}
}  // namespace

FrameOrderParams FrameOrderParams::of(const sensors::SensorConfig& rig,
                                      double imuWaitS,
                                      const std::string& program)
{
	FrameOrderParams p;
	p.program = program;
	p.sensors = rig.sensors;
	p.imuOffsetS = rig.calibration.time_offset_s;
	p.imuWaitS = imuWaitS;
	p.camera = rig.camera;
	p.depthCorrection = rig.depth_correction;
	return p;
}

FrameOrder::FrameOrder(FrameOrderParams p)
    : p_(std::move(p)),
      depthCorrection_(p_.depthCorrection),
      lastImuT_(kNever),
      newestT_(kNever),
      lastScanT_(kNever)
{
}

bool FrameOrder::ready(const SourceFrame& f) const
{
	return f.t + p_.imuOffsetS <= lastImuT_ || newestT_ - f.t > p_.imuWaitS;
}

void FrameOrder::accept(SourceFrame&& f)
{
	lastScanT_ = f.t;
	newestT_ = std::max(newestT_, f.t);
	waiting_.push_back(std::move(f));
}

void FrameOrder::tell(Warning::Kind kind, const std::string& where,
                      std::string text) const
{
	if (p_.warnings) reportWarning(p_.warn, {kind, where, std::move(text)});
}

void FrameOrder::dropHeld(const InputPlace& at, const char* why)
{
	st_.scansBadStamp++;
	tell(Warning::Kind::Warning, at.path ? *at.path : "input",
	     mrpt::format("3D scan #%zu (t %.6f) is %.6g s after the previous "
	                  "scan and %s: a stray timestamp; skipped",
	                  held_->index, held_->t, held_->t - lastScanT_, why));
	// the observations read before it stay, in order
	input_.insert(input_.begin(), held_->before.begin(), held_->before.end());
	held_.reset();
}

bool FrameOrder::imuStampUsable(const mrpt::obs::CObservationIMU::Ptr& imu,
                                double t, const std::string& where)
{
	if (!(t <= imuStampT_)) return true;
	if (st_.imuOutOfOrder++ == 0)
		tell(Warning::Kind::Warning, where,
		     mrpt::format("IMU sample '%s' at t %.6f is not after the "
		                  "previous one (t %.6f): skipped (the next ones "
		                  "too, counted in the summary, not warned about)",
		                  imu->sensorLabel.c_str(), t, imuStampT_));
	return false;
}

void FrameOrder::useImu(const mrpt::obs::CObservationIMU::Ptr& imu, double t,
                        const std::string& where, size_t entry)
{
	imuStampT_ = t;
	const std::string bad = rejected_.check(*imu, t);
	if (bad.empty())
	{
		imu_.push_back(imu);
		lastImuT_ = std::max(lastImuT_, t);
	}
	else
		tell(Warning::Kind::Warning, where,
		     mrpt::format("observation #%zu (IMU, t %.6f): %s; sample not "
		                  "used (%zu so far)",
		                  entry, t, bad.c_str(), rejected_.count()));
	st_.imuRejected = rejected_.count();
}

void FrameOrder::dropHeldImu(const std::string& where, const char* why)
{
	if (st_.imuBadStamp++ == 0)
		tell(Warning::Kind::Warning, where,
		     mrpt::format("IMU sample '%s' at t %.6f is %.6g s after the "
		                  "previous one and %s: a stray timestamp; skipped "
		                  "(the next ones too, counted in the summary, not "
		                  "warned about)",
		                  heldImu_->sensorLabel.c_str(), heldImuT_,
		                  heldImuT_ - imuStampT_, why));
	heldImu_.reset();
}

void FrameOrder::release(bool all)
{
	while (!waiting_.empty() && (all || ready(waiting_.front())))
	{
		SourceFrame f = std::move(waiting_.front());
		waiting_.pop_front();
		f.imu.swap(imu_);
		imu_.clear();
		f.imuRejected = rejected_.upTo(f.t + p_.imuOffsetS);
		// the depth distortion corrected once, for every stage and for the
		// written scan
		depthCorrection_.apply(*f.scan, p_.camera);
		released_.push_back(std::move(f));
	}
}

void FrameOrder::skipOtherImu(const mrpt::obs::CObservationIMU& imu,
                              uint8_t channels, const std::string& where)
{
	st_.otherSkipped++;
	auto& o = st_.imuOtherLabels[imu.sensorLabel];
	o.channels |= channels;
	if (o.samples++ == 0)
		tell(Warning::Kind::Warning, where,
		     "IMU samples labelled " + quoted(imu.sensorLabel) + " (" +
		         imuChannelNames(channels) +
		         ") are not used: [sensors] imu_label is " +
		         quoted(p_.sensors.imu_label));
}

void FrameOrder::noteFirstImu(const mrpt::obs::CObservationIMU& imu,
                              uint8_t channels, const std::string& where)
{
	const std::string which = "the IMU labelled " + quoted(imu.sensorLabel);
	if (channels & kImuGyro)
		tell(Warning::Kind::Info, where,
		     "using " + which + " (" + imuChannelNames(channels) + ")");
	else
		tell(Warning::Kind::Warning, where,
		     which + " measures " + imuChannelNames(channels) +
		         ": without a gyro the egomotion cannot use it (frames run "
		         "as vision, flagged imu_missing)");
}

void FrameOrder::settleHeldImu(double t, const std::string& where)
{
	// the sample after a far one: it follows within the gap (the recording
	// jumped, both are used) or the far stamp was stray
	if (followsHeld(t, heldImuT_))
	{
		useImu(heldImu_, heldImuT_, where, heldImuEntry_);
		heldImu_.reset();
	}
	else
		dropHeldImu(where, "the next sample is not");
}

FrameOrder::Pushed FrameOrder::pushImu(
    const mrpt::obs::CObservationIMU::Ptr& imu, double t, const InputPlace& at,
    const std::string& where)
{
	const uint8_t channels = imuChannels(*imu);
	if (!labelMatches(p_.sensors.imu_label, imu->sensorLabel))
	{
		skipOtherImu(*imu, channels, where);
		return Pushed::Skipped;
	}
	// at the start, which IMU the run uses and what it measures (its count:
	// in the summary; counting first would read the input twice)
	if (st_.imuRead++ == 0) noteFirstImu(*imu, channels, where);
	st_.imuChannels |= channels;
	if (p_.keepInput) input_.push_back(imu);
	if (heldImu_) settleHeldImu(t, where);
	if (!imuStampUsable(imu, t, where)) return Pushed::Taken;
	if (farAhead(t, imuStampT_))
	{
		heldImu_ = imu;  // the next sample decides
		heldImuT_ = t;
		heldImuEntry_ = at.entry;
	}
	else
		useImu(imu, t, where, at.entry);
	return Pushed::Taken;
}

void FrameOrder::noteNoImuYet(const std::string& where)
{
	tell(Warning::Kind::Info, where,
	     "no IMU sample " +
	         (p_.sensors.imu_label.empty()
	              ? std::string("of any label")
	              : "labelled " + quoted(p_.sensors.imu_label)) +
	         " before the second 3D scan (" +
	         (st_.imuOtherLabels.empty()
	              ? "none in the input so far"
	              : "only under other labels so far: [sensors] imu_label") +
	         "): frames without one run without IMU data (imu_missing)");
}

void FrameOrder::settleHeldScan(double t, const InputPlace& at)
{
	// this scan follows the held one: the recording jumped
	if (followsHeld(t, held_->t))
	{
		accept(std::move(*held_));
		held_.reset();
	}
	else
		dropHeld(at, "the next scan is not");
}

bool FrameOrder::sameImageSize(const mrpt::obs::CObservation3DRangeScan& scan,
                               size_t idx, const std::string& where)
{
	if (!scan.hasRangeImage) return true;
	const std::string size = std::to_string(scan.rangeImage.cols()) + "x" +
	                         std::to_string(scan.rangeImage.rows());
	if (firstSize_.empty())
	{
		firstSize_ =
		    size + " (3D scan #" + std::to_string(idx) + " of " + where + ")";
		return true;
	}
	if (firstSize_.compare(0, size.size() + 1, size + " ") == 0) return true;
	error_ = where + ": 3D scan #" + std::to_string(idx) + " has a " + size +
	         " depth image where the run's first had " + firstSize_ +
	         ": one run takes one image size (camera mode)";
	ended_ = true;
	return false;
}

FrameOrder::Pushed FrameOrder::pushScan(
    const mrpt::obs::CObservation3DRangeScan::Ptr& scan, double t,
    const std::string& where, double inputFraction, const InputPlace& at)
{
	if (!labelMatches(p_.sensors.rgbd_label, scan->sensorLabel))
	{
		st_.otherSkipped++;
		return Pushed::Skipped;
	}
	const size_t idx = scanIndex_++;
	// the second scan and still no IMU sample of the label: said now, not
	// only in the summary
	if (++st_.scansRead == 2 && st_.imuRead == 0) noteNoImuYet(where);
	if (held_) settleHeldScan(t, at);
	if (idx > p_.frames.last)
	{
		ended_ = true;  // the range is read
		return Pushed::End;
	}
	if (!p_.frames.contains(idx)) return Pushed::Skipped;
	if (t <= lastScanT_)
	{
		st_.scansOutOfOrder++;
		tell(Warning::Kind::Warning, where,
		     "3D scan #" + std::to_string(idx) +
		         " has a timestamp not after the previous one; skipped");
		return Pushed::Skipped;
	}
	if (!sameImageSize(*scan, idx, where)) return Pushed::End;
	SourceFrame f;
	f.scan = scan;
	f.index = idx;
	f.t = t;
	f.cost = cost_;
	f.inputFraction = inputFraction;
	f.before.swap(input_);
	input_.clear();
	cost_ = {};
	if (farAhead(t, lastScanT_))
	{
		held_ = std::move(f);  // the next scan decides
		return Pushed::Skipped;
	}
	accept(std::move(f));
	return Pushed::Taken;
}

bool FrameOrder::push(const mrpt::obs::CObservation::Ptr& obs,
                      const InputPlace& at, const InputCost& cost,
                      double inputFraction)
{
	using mrpt::obs::CObservation3DRangeScan;
	using mrpt::obs::CObservationIMU;
	if (ended_ || !obs) return !ended_;
	add(cost_, cost);
	static const std::string kInput = "input";
	const std::string& where = at.path ? *at.path : kInput;  // no copy
	const double t = mrpt::Clock::toDouble(obs->timestamp);
	Pushed step = Pushed::Taken;
	if (auto imu = std::dynamic_pointer_cast<CObservationIMU>(obs))
		step = pushImu(imu, t, at, where);
	else if (auto scan =
	             std::dynamic_pointer_cast<CObservation3DRangeScan>(obs))
		step = pushScan(scan, t, where, inputFraction, at);
	else
		st_.otherSkipped++;
	if (step != Pushed::Taken) return step == Pushed::Skipped;
	newestT_ = std::max(newestT_, t);
	release(false);
	return true;
}

uint8_t imuChannels(const mrpt::obs::CObservationIMU& imu)
{
	// what the egomotion reads from it (one home: sensors::imuSampleFrom)
	const sensors::ImuSample s = sensors::imuSampleFrom(imu);
	return uint8_t((s.hasGyro ? kImuGyro : 0) | (s.hasAcc ? kImuAccel : 0) |
	               (s.hasMag ? kImuMag : 0));
}

std::string imuChannelNames(uint8_t c)
{
	std::string s;
	for (const auto& [bit, name] :
	     {std::pair{kImuGyro, "gyro"}, {kImuAccel, "accel"}, {kImuMag, "mag"}})
		if (c & bit) s += (s.empty() ? "" : " + ") + std::string(name);
	return s.empty() ? "no gyro, accel or mag" : s;
}

bool imuMostlySkipped(const FrameOrderStats& s)
{
	const size_t unusable = s.imuRejected + s.imuOutOfOrder + s.imuBadStamp;
	return s.imuRead > 0 && 2 * unusable > s.imuRead;
}

std::vector<std::string> imuNotes(const FrameOrderStats& s,
                                  const std::string& label)
{
	std::vector<std::string> notes;
	// Samples whose stamp or values could not be used: most of them, and
	// the IMU was in effect absent.
	const size_t unusable = s.imuRejected + s.imuOutOfOrder + s.imuBadStamp;
	if (imuMostlySkipped(s))
		notes.push_back(
		    "the IMU was mostly unusable: " + std::to_string(unusable) +
		    " of its " + std::to_string(s.imuRead) + " samples skipped (" +
		    std::to_string(s.imuOutOfOrder) + " out of order or repeated, " +
		    std::to_string(s.imuBadStamp) + " with a stray stamp, " +
		    std::to_string(s.imuRejected) +
		    " with a value not finite or beyond range): frames without IMU "
		    "data ran as vision (imu_missing, imu_gap)");
	const std::string which =
	    label.empty() ? "of any label" : "labelled " + quoted(label);
	if (s.imuRead > 0)
	{
		std::string n = "IMU " + which + ": " + std::to_string(s.imuRead) +
		                " samples (" + imuChannelNames(s.imuChannels) + ")";
		if (!(s.imuChannels & kImuGyro))
			n += "; without a gyro the egomotion cannot use them (it takes "
			     "the rotation between frames from the gyro): its frames ran "
			     "as vision, flagged imu_missing";
		notes.push_back(n);
	}
	for (const auto& [other, st] : s.imuOtherLabels)
		notes.push_back(
		    std::to_string(st.samples) + " IMU samples labelled " +
		    quoted(other) + " (" + imuChannelNames(st.channels) +
		    ") were not used: [sensors] imu_label is " + quoted(label) +
		    (s.imuRead == 0 ? " (set it to " + quoted(other) + " to use them)"
		                    : ""));
	return notes;
}

void FrameOrder::finish(const InputPlace& at)
{
	if (held_) dropHeld(at, "it is the last scan");
	if (heldImu_)
		dropHeldImu(at.path ? *at.path : std::string("input"),
		            "it is the last sample");
	ended_ = true;
	release(true);
}

std::optional<SourceFrame> FrameOrder::pop()
{
	if (released_.empty()) return std::nullopt;
	SourceFrame f = std::move(released_.front());
	released_.pop_front();
	return f;
}

std::vector<mrpt::obs::CObservation::Ptr> FrameOrder::takeTrailing()
{
	std::vector<mrpt::obs::CObservation::Ptr> v;
	v.swap(input_);
	return v;
}

/** Observations read ahead: a few frames of a VGA rawlog with its IMU. */
constexpr size_t kReadAhead = 24;

RawlogFrameSource::RawlogFrameSource(std::vector<std::string> paths,
                                     FrameOrderParams p, bool readThread)
    : paths_(std::move(paths)), order_(std::move(p))
{
	if (paths_.empty()) throw std::invalid_argument("no input rawlog given");
	input_ = std::make_unique<ReadAhead>(paths_, kReadAhead, readThread);
}

RawlogFrameSource::~RawlogFrameSource() = default;

std::optional<SourceFrame> RawlogFrameSource::next()
{
	for (;;)
	{
		if (auto f = order_.pop()) return f;
		if (ended_) return std::nullopt;
		ReadAhead::Item item;
		InputCost cost;
		bool more = true;
		try
		{
			item = input_->next(&cost.waitMs);
		}
		catch (const std::exception& e)
		{
			// a truncated or missing input ends it like its end: every
			// frame read whole is still released
			error_ = e.what();
			more = false;
		}
		if (more && item.obs)
		{
			lastFile_ = item.file;
			cost.readMs = item.readMs;
			cost.readCpuMs = item.readCpuMs;
			more = order_.push(item.obs, {&paths_[item.file], item.entry}, cost,
			                   item.inputFraction);
			if (!more && error_.empty()) error_ = order_.error();
			if (more) continue;
		}
		order_.finish({&paths_[lastFile_], 0});
		ended_ = true;
	}
}

}  // namespace bims::source
