// Replays a rawlog through an Odometry (bims-odom, bims-calib-imu,
// bims-calib-depth): the frames of RawlogFrameSource (the one ordering rule,
// bims/source/frame_source.h) with the IMU samples before each.
#pragma once

#include <bims/ego/odometry.h>
#include <bims/source/frame_source.h>

#include <functional>
#include <string>
#include <vector>

namespace bims::apps
{
struct ReplayOptions
{
	double imu_wait_s = 0.2;  ///< max wait for the IMU behind a frame [s]
	size_t max_frames = 0;    ///< stop after this many frames (0 = all)
	bool progress = true;     ///< progress line on stderr
	/** Folder of moving masks NNNNNN.png (3D-scan index from 0, 8-bit, non-zero
	 * = moving; bims-run's OUT/masks, or a simulation's ground truth): scan
	 * k-1's mask is handed to frame k, as bims-run feeds its segmentation
	 * back. Empty: none (moving content is then left to the alignment's robust
	 * weights). */
	std::string masks_dir;
};

struct ReplayStats
{
	size_t frames = 0;      ///< RGB-D frames processed
	size_t imu = 0;         ///< IMU observations fed
	size_t flagged = 0;     ///< frames with a failure flag (!ok())
	size_t otherLabel = 0;  ///< observations skipped (label or class)
	size_t masksUsed = 0;   ///< frames given a mask from masks_dir
	/** IMU samples not used: a field not finite or beyond any sensor's range
	 * (bims::imuSampleProblem; a warning each, the frame flagged
	 * imu_rejected). */
	size_t imuRejected = 0;
	/** What to say about the IMU (imuNotes()). */
	std::vector<std::string> imuNotes;
};

using FrameCallback = std::function<void(
    const ego::FrameEgomotion&, const mrpt::obs::CObservation3DRangeScan&)>;
using ImuCallback = std::function<void(const sensors::ImuSample&)>;

/** Runs \a odo over the rawlog at \a path. Throws RawlogError on a
 * truncated or corrupt file (after the frames before it were processed). */
ReplayStats replayRawlog(const std::string& path, ego::Odometry& odo,
                         const FrameCallback& onFrame,
                         const ReplayOptions& opt = {},
                         const ImuCallback& onImu = {});

}  // namespace bims::apps
