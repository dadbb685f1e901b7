// The one home of the rule that orders a recording's observations into the
// frames every program runs: bims-run (batch), the viewer (replay), bims-grab
// --live-segmentation (live) and bims-odom all take their frames from here.
//
// FrameOrder is the rule, fed one observation at a time in the input's order
// (push); RawlogFrameSource feeds it from rawlog files (read ahead on a thread
// or not) and hands the frames out one by one (next).
//
// The rule, per observation:
//  - an observation whose sensorLabel is not [sensors] rgbd_label (3D scans)
//    or imu_label (IMU) is skipped (counted; an empty label takes all); IMU
//    samples of another label are counted by label, and the first of each
//    label is warned about (no IMU is left unused silently);
//  - an IMU sample is checked (bims::RejectedImuSamples: a field not finite
//    or beyond any sensor's range is warned about and not used);
//  - an IMU sample stamped not after the previous one used is skipped; one
//    stamped more than kMaxScanGapS after it is held until the next sample
//    says whether the recording jumped (kept) or the stamp is stray
//    (skipped); the first of each kind is warned about, all are counted;
//  - 3D scans are numbered from 0 in input order (the index bims-run names
//    its files by); a scan outside the frame range is skipped, and reading
//    stops after the range's last;
//  - a scan stamped not after the previous frame's is skipped (warned about);
//    a scan stamped more than kMaxScanGapS after it is held back until the
//    next scan says whether the recording jumped (it follows within the
//    gap: kept) or the stamp is stray (skipped, warned about);
//  - every scan of a run has the size of the first: another size ends the
//    input with an error (one camera mode per run);
//  - a frame is released once the IMU stream has passed its time (+
//    [calibration] time_offset_s), or once data more than [pipeline]
//    imu_wait_s newer has been read (IMU late or absent), or at the end, so
//    that its attitude is interpolated rather than extrapolated. It carries
//    the IMU samples read since the frame before (feed them first, in order);
//  - the sensor's depth distortion ([depth_correction]) is corrected once,
//    in the released scan, for every stage and for the scan a run writes.
#pragma once

#include <bims/common/imu_check.h>
#include <bims/common/warnings.h>
#include <bims/sensors/depth_correction.h>
#include <bims/sensors/imu_sample.h>
#include <bims/sensors/params.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <cstddef>
#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace bims::source
{
/** A scan stamped more than this after the previous one [s] is held back:
 * kept when the next scan follows it within this gap (the recording jumped,
 * e.g. a second rawlog), skipped with a warning when the next scan does not
 * (a stray stamp), or when it is the last. */
constexpr double kMaxScanGapS = 10.0;

/** 3D-scan indices A to B (bims-run --frames A:B). */
struct FrameRange
{
	size_t first = 0;
	size_t last = static_cast<size_t>(-1);
	bool contains(size_t i) const { return i >= first && i <= last; }
	/** B given (not "A:"). */
	bool bounded() const { return last != static_cast<size_t>(-1); }
	/** "A:B" ("A:" when open-ended), for messages. */
	std::string toString() const
	{
		return std::to_string(first) + ":" +
		       (bounded() ? std::to_string(last) : std::string());
	}
	/** Parses "A:B"; throws std::invalid_argument on bad text or A > B. */
	static FrameRange parse(const std::string& s);
};

/** For --frames A:B, before any work: throws std::invalid_argument naming
 * the range and the inputs' 3D-scan count unless \a rawlogs hold the scans
 * A to B (A, when open-ended). Reads them up to that scan
 * (bims::count3DScans), counting the scans with label \a rgbdLabel (all
 * when empty), as the frame sources number them. Nothing to check for the
 * whole input, nor when an input cannot be read that far (missing,
 * truncated): the run reports that as it would without a range. (A
 * program's --frames option: bims/apps/frame_range_option.h.) */
void checkFrameRangeInInputs(const FrameRange& range,
                             const std::vector<std::string>& rawlogs,
                             const std::string& rgbdLabel);

/** What the rule takes from an experiment's configuration. */
struct FrameOrderParams
{
	/** The program the frames are read for (the callers' name for the
	 * run; the warnings are worded by the program's \a warn). */
	std::string program = "bims";
	/** Report what is skipped (counted in FrameOrderStats either way)
	 * through \a warn: off for a pass that only indexes the input. */
	bool warnings = true;
	/** Receives the warnings and notes (what is skipped, which IMU is
	 * used): the program's own (bims::programWarnings()) unless set. */
	WarningCallback warn = programWarnings();
	sensors::SensorsParams sensors;
	/** IMU stamp = camera stamp + offset for the same instant [s]. */
	double imuOffsetS = 0;
	/** A frame waits at most this much newer data for the IMU [s]. */
	double imuWaitS = 0.2;
	FrameRange frames;
	sensors::CameraParams camera;  ///< for the depth correction's intrinsics
	sensors::DepthCorrectionParams depthCorrection;
	/** Keep the IMU observations to write beside the frames
	 * (SourceFrame::before, FrameOrder::takeTrailing): a labelled copy of
	 * the input. */
	bool keepInput = false;

	/** The rule as the sensor rig \a rig configures it (an experiment's
	 * ego::EgoConfig is one), with \a imuWaitS ([pipeline]). */
	static FrameOrderParams of(const sensors::SensorConfig& rig,
	                           double imuWaitS, const std::string& program);
};

/** Time spent getting the input of a frame (RawlogFrameSource). */
struct InputCost
{
	double readMs = 0;     ///< reading and decoding its observations
	double readCpuMs = 0;  ///< the same in CPU time (the reading thread's)
	double waitMs = 0;     ///< the caller blocked waiting for them
};

/** One RGB-D frame, released by the rule. */
struct SourceFrame
{
	/** Loaded (external images too) and depth corrected. */
	mrpt::obs::CObservation3DRangeScan::Ptr scan;
	size_t index = 0;  ///< 3D-scan index in the input (from 0)
	double t = 0;      ///< its stamp [s] (mrpt::Clock::toDouble)
	/** The usable IMU samples read since the previous frame was released, in
	 * input order: feed them before processing this frame. */
	std::vector<mrpt::obs::CObservationIMU::Ptr> imu;
	/** An IMU sample stamped at or before this frame (time_offset_s
	 * applied) was rejected since the previous frame. */
	bool imuRejected = false;
	/** keepInput: the IMU observations (usable or not) between the previous
	 * frame and this one in the input, to write before it. */
	std::vector<mrpt::obs::CObservation::Ptr> before;
	InputCost cost;  ///< of the observations up to this scan
	/** Share of the input read with it (0..1; 0 when unknown). */
	double inputFraction = 0;
};

/** What an IMU's samples measure: bits of ImuChannel. */
enum ImuChannel : uint8_t
{
	kImuGyro = 1,
	kImuAccel = 2,
	kImuMag = 4
};
/** The channels of one sample, as the egomotion reads them
 * (sensors::imuSampleFrom: all three axes present and finite). */
uint8_t imuChannels(const mrpt::obs::CObservationIMU& imu);
/** "gyro + accel + mag", "accel", ..., "no gyro, accel or mag". */
std::string imuChannelNames(uint8_t channels);

/** The IMU samples of one sensor label. */
struct ImuLabelStats
{
	size_t samples = 0;
	uint8_t channels = 0;  ///< ImuChannel bits seen in any of them
};

/** What the rule did with the observations it was given. */
struct FrameOrderStats
{
	size_t scansRead = 0;        ///< 3D scans with the label
	size_t scansOutOfOrder = 0;  ///< skipped: stamp not after the previous
	size_t scansBadStamp = 0;    ///< skipped: a stray stamp
	size_t imuRead = 0;          ///< IMU samples with the label
	uint8_t imuChannels = 0;     ///< what they measure (ImuChannel bits)
	size_t imuRejected = 0;      ///< of them not used (warned about)
	size_t imuOutOfOrder = 0;    ///< skipped: stamp not after the previous
	size_t imuBadStamp = 0;      ///< skipped: a stray stamp (far ahead)
	size_t otherSkipped = 0;     ///< another label, or another class
	/** IMU samples of another label than [sensors] imu_label (among
	 * otherSkipped), by label. */
	std::map<std::string, ImuLabelStats> imuOtherLabels;
};

/** More than half of the IMU's samples were skipped (stamp out of order,
 * repeated or stray, or a value rejected). */
bool imuMostlySkipped(const FrameOrderStats& s);

/** What a run should say about its IMU (bims-run's and bims-odom's
 * summaries): the label used, its samples and channels, a gyro-less IMU
 * the egomotion cannot use, and the IMU samples left unused under other
 * labels. \a label: [sensors] imu_label. */
std::vector<std::string> imuNotes(const FrameOrderStats& s,
                                  const std::string& label);

/** Where an observation comes from, for the warnings. */
struct InputPlace
{
	const std::string* path = nullptr;  ///< file (or device) name
	size_t entry = 0;                   ///< its observation index in that file
};

/** The rule (the header's comment), fed in input order. */
class FrameOrder
{
 public:
	explicit FrameOrder(FrameOrderParams p);

	/** Takes the input's next observation (its reading cost added to the
	 * next frame's), releasing the frames that became ready (pop). Returns
	 * false once the input should not be read further: past the frame
	 * range, or an input error (error()). */
	bool push(const mrpt::obs::CObservation::Ptr& obs, const InputPlace& at,
	          const InputCost& cost = {}, double inputFraction = 0);
	/** The end of the input: every frame held or waiting is released (the
	 * last held stray stamp is skipped). */
	void finish(const InputPlace& at);
	/** The next released frame, if any. */
	std::optional<SourceFrame> pop();
	/** keepInput: the observations read after the last frame (after
	 * finish(): write them last). */
	std::vector<mrpt::obs::CObservation::Ptr> takeTrailing();

	/** An input error that ended the input (another image size); the
	 * frames before it are still released. */
	const std::string& error() const { return error_; }
	const FrameOrderStats& stats() const { return st_; }
	const FrameOrderParams& params() const { return p_; }

 private:
	bool ready(const SourceFrame& f) const;
	void accept(SourceFrame&& f);
	/** Hands a warning (or a note) about \a where to p_.warn, if
	 * p_.warnings. */
	void tell(Warning::Kind kind, const std::string& where,
	          std::string text) const;
	/** What push() did with an observation: taken (the frames that became
	 * ready are released), skipped (nothing more to do), or the end of the
	 * input. */
	enum class Pushed
	{
		Taken,
		Skipped,
		End
	};
	/** push() of an IMU sample stamped \a t read from \a where. */
	Pushed pushImu(const mrpt::obs::CObservationIMU::Ptr& imu, double t,
	               const InputPlace& at, const std::string& where);
	/** push() of a 3D scan. */
	Pushed pushScan(const mrpt::obs::CObservation3DRangeScan::Ptr& scan,
	                double t, const std::string& where, double inputFraction,
	                const InputPlace& at);
	/** Counts a sample of another IMU label (warned once per label). */
	void skipOtherImu(const mrpt::obs::CObservationIMU& imu, uint8_t channels,
	                  const std::string& where);
	/** The first sample of the IMU used: which it is and what it measures. */
	void noteFirstImu(const mrpt::obs::CObservationIMU& imu, uint8_t channels,
	                  const std::string& where);
	/** The sample after a held one (a far stamp) decides it. */
	void settleHeldImu(double t, const std::string& where);
	/** The second scan and still no IMU sample of the label: said now. */
	void noteNoImuYet(const std::string& where);
	/** The scan after a held one (a far stamp) decides it. */
	void settleHeldScan(double t, const InputPlace& at);
	/** The one image size of a run: false (error_ set) if \a scan's range
	 * image differs from the first one's. */
	bool sameImageSize(const mrpt::obs::CObservation3DRangeScan& scan,
	                   size_t idx, const std::string& where);
	void dropHeld(const InputPlace& at, const char* why);
	void release(bool all);
	/** The stamp rule of IMU samples: false if \a imu is skipped or held. */
	bool imuStampUsable(const mrpt::obs::CObservationIMU::Ptr& imu, double t,
	                    const std::string& where);
	void useImu(const mrpt::obs::CObservationIMU::Ptr& imu, double t,
	            const std::string& where, size_t entry);
	/** Skips the held IMU sample (a stray stamp): counted, warned once. */
	void dropHeldImu(const std::string& where, const char* why);

	FrameOrderParams p_;
	FrameOrderStats st_;
	RejectedImuSamples rejected_;
	sensors::DepthCorrection depthCorrection_;
	std::deque<SourceFrame> waiting_;  ///< accepted, waiting for the IMU
	std::deque<SourceFrame> released_;
	std::optional<SourceFrame> held_;  ///< a far stamp, the next scan decides
	/** An IMU sample of a far stamp, the next sample decides (with the
	 * place it was read at). */
	mrpt::obs::CObservationIMU::Ptr heldImu_;
	double heldImuT_ = 0;
	size_t heldImuEntry_ = 0;
	/** Stamp of the last IMU sample whose stamp was used. */
	double imuStampT_ = -std::numeric_limits<double>::infinity();
	std::vector<mrpt::obs::CObservationIMU::Ptr> imu_;  ///< not handed out
	std::vector<mrpt::obs::CObservation::Ptr> input_;   ///< keepInput
	InputCost cost_;  ///< since the last frame made
	double lastImuT_, newestT_, lastScanT_;
	size_t scanIndex_ = 0;
	std::string firstSize_;  ///< "WxH (3D scan #i of FILE)"
	std::string error_;
	bool ended_ = false;
};

class ReadAhead;

/** The frames of rawlog files, one file after the other, through the rule:
 * a reading error (truncated, corrupt) ends the input like its end, after
 * every frame read whole. */
class RawlogFrameSource
{
 public:
	/** \a readThread: read and decode ahead on a thread ([pipeline]
	 * read_ahead). Opening a file that cannot be read throws RawlogError. */
	RawlogFrameSource(std::vector<std::string> paths, FrameOrderParams p,
	                  bool readThread);
	~RawlogFrameSource();
	RawlogFrameSource(const RawlogFrameSource&) = delete;
	RawlogFrameSource& operator=(const RawlogFrameSource&) = delete;

	/** The next frame; nullopt at the end of the input (error() says
	 * whether an error ended it). */
	std::optional<SourceFrame> next();
	/** The reading or input error that ended the input, "" if none. */
	const std::string& error() const { return error_; }
	/** keepInput: the observations after the last frame, at the end. */
	std::vector<mrpt::obs::CObservation::Ptr> takeTrailing()
	{
		return order_.takeTrailing();
	}
	const FrameOrderStats& stats() const { return order_.stats(); }
	const std::vector<std::string>& paths() const { return paths_; }

 private:
	std::vector<std::string> paths_;
	FrameOrder order_;
	std::unique_ptr<ReadAhead> input_;
	std::string error_;
	size_t lastFile_ = 0;
	bool ended_ = false;
};

}  // namespace bims::source
