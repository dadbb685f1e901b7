// Live grabbing configured in rawlog-grabber style: one .ini section per
// sensor with driver=, plus [global]. Writes an observations-only rawlog as
// it goes, flushed after every RGB-D frame (a kill or an unplug loses at most
// the frame being written), IMU samples before the frame they precede, all
// stamps on the host clock.
//
//   [global]
//   max_frames=0          ; stop after N RGB-D frames (0 = until Ctrl-C)
//   stall_timeout_s=5     ; no RGB-D frame this long: stop with an error
//   [RGBD]
//   driver=OpenNI2        ; our source (bims/grab/openni2_source.h)
//   device_uri=           ; "" first device, Dummy, or an .oni file
//   [IMU]
//   driver=CIMUXSens_MT4  ; or RawlogImu (bims/grab/imu_source.h)
#pragma once

#include <bims/grab/imu_source.h>
#include <bims/grab/openni2_source.h>
#include <bims/io/rawlog.h>

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace bims::grab
{
/** [global] */
struct GlobalGrabParams
{
	size_t maxFrames = 0;        ///< 0 = until stopped
	double stallTimeoutS = 5.0;  ///< [s]
};

/** What a grab did. */
struct GrabStats
{
	size_t frames = 0;        ///< RGB-D frames written
	size_t imu = 0;           ///< IMU samples written
	size_t timeouts = 0;      ///< waits without an RGB-D frame
	double seconds = 0;       ///< wall time
	size_t nonMonotonic = 0;  ///< written stamps that went backwards (0)
	std::string stopReason;   ///< "max_frames", "stopped", error text
};

/** Called after each frame is written (live segmentation, preview). */
using GrabCallback =
    std::function<void(const mrpt::obs::CObservation3DRangeScan::Ptr&,
                       const std::vector<mrpt::obs::CObservationIMU::Ptr>&)>;

class Grabber
{
 public:
	/** Reads the .ini and opens every sensor. Throws ConfigError for a bad
	 * .ini (file, section and key named) and std::runtime_error when a
	 * device is missing: a clear message, never an abort. Exactly one
	 * OpenNI2 section is required; IMU sections are optional. */
	explicit Grabber(const mrpt::config::CConfigFileBase& cfg);
	~Grabber();

	/** Grabs until \a stop, max_frames (\a maxFrames overrides it when > 0)
	 * or an error (device lost: stopReason says so, what was written stays
	 * valid). */
	GrabStats run(RawlogWriter& out, const std::atomic<bool>& stop,
	              size_t maxFrames = 0, const GrabCallback& cb = {});

	/** One line per sensor. */
	std::vector<std::string> describe() const;
	/** The files its sensors read (a replayed IMU rawlog), for the output
	 * guard: bims-grab refuses to write over them. */
	std::vector<std::string> inputFiles() const;
	const GlobalGrabParams& global() const { return global_; }

 private:
	GlobalGrabParams global_;
	std::unique_ptr<OpenNI2Source> rgbd_;
	std::vector<std::unique_ptr<ImuSource>> imus_;
};

}  // namespace bims::grab
