// Camera trajectories in the TUM RGB-D format:
//   timestamp tx ty tz qx qy qz qw     (seconds, metres, unit quaternion)
// Each pose is T_WC: the camera {C} expressed in the world {W}.
#pragma once

#include <mrpt/poses/CPose3D.h>

#include <string>
#include <vector>

namespace bims
{
struct StampedPose
{
	double t = 0;               ///< seconds (UNIX time or sequence time)
	mrpt::poses::CPose3D T_WC;  ///< camera pose in the world frame
};
using Trajectory = std::vector<StampedPose>;

/** Reads a TUM trajectory file; '#' lines and blank lines are skipped.
 * Throws std::runtime_error naming the file and line on malformed input,
 * non-finite values, non-unit quaternions (|q| off by > 1e-3) or timestamps
 * that go backwards. */
Trajectory loadTumTrajectory(const std::string& path);

/** Writes a TUM trajectory (header comment, 6 decimals for time, 9 for
 * values), complete or not at all (writeFileAtomically). Throws
 * std::runtime_error if the file cannot be written or a pose or time is not
 * finite (naming its time; nothing is written then). */
void saveTumTrajectory(const std::string& path, const Trajectory& traj,
                       const std::string& headerComment = {});

/** The text saveTumTrajectory() writes; throws as it does (\a path named
 * in the error). */
std::string tumTrajectoryText(const std::string& path, const Trajectory& traj,
                              const std::string& headerComment = {});

/** The pose of \a traj (sorted by time) nearest to \a t, if it is less
 * than \a maxDt away [s]; else nullptr. */
const StampedPose* poseNear(const Trajectory& traj, double t, double maxDt);

/** One TUM line for a pose (no newline). */
std::string tumLine(double t, const mrpt::poses::CPose3D& T_WC);

/** The header of a TUM file: "# comment" (if any) and the column names,
 * each line ended. */
std::string tumHeader(const std::string& comment = {});

}  // namespace bims
