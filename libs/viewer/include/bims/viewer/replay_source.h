// Reading a rawlog for replay: 3D scans in file order, each released once the
// IMU samples up to its timestamp have been read (the same ordering rule as
// bims-run), so that a Pipeline fed frame by frame sees what bims-run sees.
#pragma once

#include <bims/common/rawlog.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace bims::viewer
{
/** One RGB-D frame and the IMU samples read since the previous frame (feed
 * them to the pipeline first, in order). */
struct ReplayFrame
{
	size_t index = 0;  ///< 3D-scan index in the file (from 0)
	double t = 0;      ///< scan timestamp [s] (mrpt::Clock::toDouble)
	mrpt::obs::CObservation3DRangeScan::Ptr scan;
	std::vector<mrpt::obs::CObservationIMU::Ptr> imu;
};

/** Which observations to take and how long a scan waits for the IMU. */
struct ReplaySourceParams
{
	std::string rgbdLabel;  ///< 3D-scan sensorLabel ("" = any)
	std::string imuLabel;   ///< IMU sensorLabel ("" = any)
	/** IMU stamp = camera stamp + offset for the same instant [s]. */
	double imuOffsetS = 0;
	/** A scan is released at most this much data time after its stamp even
	 * without IMU samples at its time [s]. */
	double imuWaitS = 0.1;
};

/** Sequential, restartable reader of one rawlog. */
class ReplaySource
{
 public:
	/** Opens \a path and reads it once to index the 3D scans (timestamps);
	 * throws RawlogError naming the file on a bad or truncated file, and
	 * std::runtime_error when it holds no 3D scan with the label. */
	ReplaySource(const std::string& path, const ReplaySourceParams& p);

	/** Timestamps of all matching 3D scans, in file order [s]. */
	const std::vector<double>& frameTimes() const { return times_; }
	size_t frameCount() const { return times_.size(); }
	/** Number of IMU observations in the file (any label). */
	size_t imuCount() const { return nImu_; }
	const std::string& path() const { return path_; }

	/** The next frame, or nullopt at the end of the file. */
	std::optional<ReplayFrame> next();
	/** Back to the start of the file. */
	void rewind();

 private:
	std::string path_;
	ReplaySourceParams p_;
	std::vector<double> times_;
	size_t nImu_ = 0;
	std::unique_ptr<RawlogReader> reader_;
	std::deque<ReplayFrame> pending_;
	std::vector<mrpt::obs::CObservationIMU::Ptr> imu_;
	double lastImuT_ = 0, newestT_ = 0;
	bool haveImu_ = false, haveAny_ = false, eof_ = false;
	size_t scanIndex_ = 0;
};

}  // namespace bims::viewer
