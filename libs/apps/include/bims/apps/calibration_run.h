// The calibration programs' runs over a rawlog (replayRawlog): bims-calib-imu
// (R_IC from gyro vs visual inter-frame rotations, docs/ego.md) and
// bims-calib-depth (the depth sensor's smooth distortion fitted to a static
// stretch, docs/ego.md "Depth correction"). Their mains only read the command
// line into these options and call the run.
#pragma once

#include <bims/ego/depth_correction.h>
#include <bims/ego/odometry.h>
#include <bims/ego/rotation_calibration.h>

#include <cmath>
#include <deque>
#include <optional>
#include <string>
#include <vector>

namespace bims::apps
{
/** What bims-calib-imu's command line gives. */
struct ImuCalibrationOptions
{
	std::string config;  ///< experiment .ini
	std::string rawlog;  ///< input rawlog (RGB-D + IMU)
	/** extra .ini with [calibration] [camera] [sensors] ("": none); its
	 * R_IC, if any, is the reference the estimate is compared with */
	std::string calib;
	std::optional<std::string> out;  ///< the estimate as a [calibration] .ini
	double min_angle_deg = 0.3;      ///< frame pairs rotating less: skipped
	double inlier_deg = 0.3;         ///< inlier limit on the residual
	bool progress = true;            ///< progress line on stderr
	/** a 1-sigma uncertainty beyond this is warned about [deg] */
	double max_uncertainty_deg = 1.0;
};

/** The pairs (gyro rotation, visual rotation) of consecutive frames, fed as
 * the replay goes: the IMU samples (addImu) and each frame's egomotion
 * (addFrame). The gyro is integrated over the frames' interval shifted by
 * \a time_offset_s (the IMU clock); frames out of order do not move the
 * interval's start, the first frame and failed frames give no pair. */
class RotationPairCollector
{
 public:
	explicit RotationPairCollector(double time_offset_s) : off_(time_offset_s)
	{
	}
	void addImu(const sensors::ImuSample& s) { imu_.push_back(s); }
	void addFrame(const ego::FrameEgomotion& r);
	const std::vector<ego::RotationPair>& pairs() const { return pairs_; }

 private:
	double off_;
	double tPrev_ = NAN;
	std::deque<sensors::ImuSample> imu_;
	std::vector<ego::RotationPair> pairs_;
};

/** bims-calib-imu's --out file: R_IC (row major, 9 decimals) and the time
 * offset in a [calibration] section, with a comment naming \a rawlog. */
std::string imuCalibrationIni(const Eigen::Matrix3d& R_IC, double time_offset_s,
                              const std::string& rawlog);

/** bims-calib-imu: checks that no output is an input, runs vision-only
 * odometry over the rawlog, estimates R_IC, prints it (and its angle to the
 * configured one) and writes --out. Returns the exit code (0); errors
 * (no IMU, R_IC not observable, a missing --calib) are thrown. */
int runImuCalibration(const ImuCalibrationOptions& o);

/** What bims-calib-depth's command line gives. */
struct DepthCalibrationOptions
{
	std::string config;  ///< experiment .ini ([camera], [sensors])
	std::string rawlog;  ///< input rawlog (RGB-D)
	std::string frames;  ///< --frames A:B ("": all)
	std::string poses;   ///< TUM trajectory ("": the vision odometry's)
	std::string out;     ///< where to write [depth_correction]
	/** refuse a fit correcting any pixel by more than this fraction */
	double max_correction = 0.1;
	bool progress = true;  ///< progress line on stderr
};

/** The largest |factor - 1| of correction \a p over an image of \a size
 * with intrinsics \a K. */
double largestDepthCorrection(const sensors::DepthCorrectionParams& p,
                              const Eigen::Matrix3d& K, cv::Size size);

/** bims-calib-depth: checks that no output is an input and the frame
 * range, runs frame-to-frame vision odometry on the raw depth over the
 * rawlog, fits the correction at the given or the odometry's poses, prints
 * the fit, refuses one larger than max_correction (nothing written) and
 * writes the [depth_correction] section. Returns the exit code (0); errors
 * are thrown. */
int runDepthCalibration(const DepthCalibrationOptions& o);

}  // namespace bims::apps
