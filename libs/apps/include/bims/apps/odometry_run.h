// bims-odom's run: egomotion alone over a rawlog (replayRawlog), the
// trajectory T_WC in the TUM format, an optional per-frame CSV and the
// per-stage timing summary on stderr. The program's main only reads its
// command line into OdometryRunOptions and calls runOdometry.
#pragma once

#include <bims/apps/odometry_replay.h>
#include <bims/ego/odometry.h>
#include <bims/ego/rgbd_input.h>
#include <bims/io/trajectory.h>

#include <mrpt/poses/CPose3D.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace bims::apps
{
/** What bims-odom's command line gives (nullopt: option not given). */
struct OdometryRunOptions
{
	std::string config;  ///< experiment .ini
	std::string rawlog;  ///< input rawlog
	std::string out;     ///< output TUM trajectory
	/** extra .ini whose [calibration] [camera] [sensors] override the
	 * config ("": none) */
	std::string calib;
	std::optional<std::string> mode;      ///< [odometry] mode: imu | vision
	std::optional<std::string> gyro_aid;  ///< [odometry] gyro_aid
	std::optional<std::string> csv;       ///< per-frame details
	std::optional<std::string> masks;     ///< folder of moving masks NNNNNN.png
	/** ground truth: adds the tracker's accuracy to the CSV */
	std::optional<std::string> gt;
	size_t max_frames = 0;  ///< stop after N frames (0: all)
	bool progress = true;   ///< progress line on stderr
	/** the IMU attitude filter's R_WC = R_WI R_IC at each frame's stamp
	 * (zero translation; frames without an attitude left out), TUM */
	std::optional<std::string> attitude;
	/** the odometry's R_WC levelled by the inertial filter's gravity at
	 * each frame ([inertial]; translation 0; frames the filter did not
	 * carry left out), TUM */
	std::optional<std::string> gravity_attitude;
};

/** Overrides \a ec's [calibration] [camera] [sensors] with those of the
 * .ini \a calib (checked as strictly as the config: checkIniFile,
 * checkExperimentSections); throws UsageError "CALIB: no such NOUN" (\a
 * noSuch: the NOUN) when it does not exist. bims-odom, bims-calib-imu. */
void overrideSensorSectionsFrom(ego::EgoConfig& ec, const std::string& calib,
                                const std::string& noSuch);

/** The experiment file \a path of bims-odom, bims-calib-imu and
 * bims-calib-depth (ego::EgoConfig::loadFromFile); a missing file is a
 * UsageError naming it (exit code 2). */
ego::EgoConfig egoConfigOption(const std::string& path);

/** The configuration bims-odom runs: \a o.config, then \a o.calib's sensor
 * sections, --mode and --gyro-aid. Throws UsageError for a missing --calib
 * file or a bad --mode / --gyro-aid value, ConfigError when mode imu has
 * no [calibration] R_IC. */
ego::EgoConfig odometryConfig(const OdometryRunOptions& o);

/** How well the tracker followed the truth over one frame pair. */
struct TrackerTruth
{
	double rate_deg_s = NAN;       ///< true angular rate [deg/s]
	int attempted_with_depth = 0;  ///< features attempted with a true match
	int tracked_within_2px = 0;    ///< tracks within 2 px of the truth
};

/** Tracker accuracy of \a r against the true relative pose \a T_CprevC
 * (T_{C(t-1) C(t)}) over \a dt seconds: the previous image's features
 * (depth of \a prevDepth) moved by the truth into the current image
 * (intrinsics \a K). */
TrackerTruth trackerAgainstTruth(const ego::FrameEgomotion& r,
                                 const cv::Mat& prevDepth,
                                 const Eigen::Matrix3d& K,
                                 const mrpt::poses::CPose3D& T_CprevC,
                                 double dt);

/** The header of bims-odom's --csv (with its newline). */
const char* odometryCsvHeader();

/** One line of bims-odom's --csv for frame \a r (with its newline). */
std::string odometryCsvLine(const ego::FrameEgomotion& r,
                            const TrackerTruth& truth);

/** bims-odom: checks that no output is an input (checkOutputsSpareInputs),
 * runs the odometry of \a o over its rawlog, writes the trajectory (and
 * the CSV) and prints the summary on stderr. Returns the program's exit
 * code (0); errors are thrown. */
int runOdometry(const OdometryRunOptions& o);

}  // namespace bims::apps
