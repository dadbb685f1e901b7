// Per-frame and per-sample quality flags of the egomotion stage. A flagged
// frame still carries a pose (the best available); the flags say what was
// missing so that callers never take a degraded estimate for a good one.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

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
	/** The pose was aligned to a keyframe of the static scene ([anchor]). */
	kFlagAnchored = 1u << 11,
	/** [anchor] enabled but the alignment failed or was rejected (too few
	 * inliers, a correction beyond max_correction_*): the frame-to-frame
	 * pose is kept. */
	kFlagAnchorFailed = 1u << 12,
	/** This frame's predecessor became a keyframe. */
	kFlagNewKeyframe = 1u << 13,
	/** lost_frames frames in a row without an accepted alignment: the
	 * anchoring restarts from this frame (its pose is the frame-to-frame
	 * one; nothing jumps; the older keyframes stay). */
	kFlagAnchorLost = 1u << 14,
	/** The moving mask covered more than [anchor] max_excluded_fraction of
	 * the image: not used for this frame (the feedback must not starve the
	 * tracker). */
	kFlagMaskIgnored = 1u << 15,
	/** Anchored with a correction beyond [anchor] max_correction_*: the
	 * frame fits a keyframe almost entirely, the pose had drifted and jumps
	 * back (relocalisation). */
	kFlagAnchorRelocalised = 1u << 16,
	/** An IMU sample in this frame's interval was rejected (a field not
	 * finite or beyond any sensor's range; bims::imuSampleProblem) and
	 * not used. Set by bims-run. */
	kFlagImuRejected = 1u << 17,
	/** The frame has no image (depth only): no features were tracked; its
	 * rotation is the IMU's (else constant velocity) and its motion is
	 * measured only by the keyframe alignment's geometric term (a frame
	 * without kFlagAnchored is not measured). */
	kFlagNoImage = 1u << 18,
	/** Part of the fed-back moving mask was not used: the previous frame's
	 * alignment found those regions on the static keyframe's surface
	 * ([anchor] mask_veto_consistent). */
	kFlagMaskVetoed = 1u << 19,
	/** The depth alignment left directions of the position unconstrained
	 * ([inertial] degenerate_sigma_m; FrameEgomotion::degenerate says how
	 * many): along them the inertial prediction stands. */
	kFlagDegenerate = 1u << 20,
	/** The alignment disagreed with the inertial prediction beyond
	 * [inertial] gate_sigma: refused, the prediction stands. */
	kFlagInertialRejected = 1u << 21,
	/** Part of the interval had no accelerometer sample (a gap, an IMU
	 * that stopped or runs on another clock): the motion prior (constant
	 * velocity) carried it. */
	kFlagInertialPrior = 1u << 22,
	/** An accelerometer sample at or beyond [inertial] accel_range_ms2 was
	 * left out (saturated). */
	kFlagAccelSaturated = 1u << 23,
};

/** The names of the set bits, in bit order ("imu_gap", "too_few_tracks");
 * the one table of flag names. */
std::vector<const char*> flagNames(uint32_t flags);

/** "imu_gap|too_few_tracks" style text ("ok" for none). */
std::string flagsToString(uint32_t flags);

}  // namespace bims::ego
