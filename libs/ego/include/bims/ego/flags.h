// Per-frame and per-sample quality flags of the egomotion stage. A flagged
// frame still carries a pose (the best available); the flags say what was
// missing so that callers never take a degraded estimate for a good one.
#pragma once

#include <cstdint>
#include <string>

namespace bims::ego
{
enum EgoFlag : uint32_t
{
	kFlagNone = 0,
	kFlagFirstFrame = 1u << 0,  ///< first frame: pose is the reference
	kFlagImuMissing = 1u << 1,  ///< no attitude for this time (no IMU data)
	kFlagImuGap = 1u << 2,      ///< IMU samples around this time too far apart
	kFlagTooFewTracks = 1u << 3,   ///< < min_tracks features with depth
	kFlagTooFewInliers = 1u << 4,  ///< robust fit failed: motion not updated
	kFlagOutOfOrder = 1u << 5,     ///< timestamp not after the previous one
	kFlagConstVelPrediction = 1u << 6,  ///< KLT seeded without gyro data
	kFlagAccelGated = 1u << 7,  ///< accelerometer rejected (linear accel.)
	kFlagMagGated = 1u << 8,    ///< magnetometer rejected (disturbance)
	kFlagBadImage = 1u << 9,    ///< no usable intensity or depth image
	/** mode = imu: the first IMU attitude came after the first frame; the
	 * world's rotation was re-anchored on it (T_WC jumps, T_CprevC is the
	 * vision estimate). */
	kFlagWorldReanchored = 1u << 10,
};

/** "imu_gap|too_few_tracks" style text ("ok" for none). */
std::string flagsToString(uint32_t flags);

}  // namespace bims::ego
