// Trajectory metrics of the TUM RGB-D benchmark (Sturm et al., IROS 2012):
// absolute trajectory error (evaluate_ate.py) and relative pose error
// (evaluate_rpe.py with a fixed delta in seconds). Exact definitions:
// docs/eval.md.
#pragma once

#include <bims/eval/association.h>
#include <bims/io/json.h>
#include <bims/io/trajectory.h>
#include <mrpt/poses/CPose3D.h>

#include <string>
#include <vector>

namespace bims::eval
{
/** Summary statistics of a list of non-negative errors (unit of the list). */
struct ErrorStats
{
	size_t count = 0;
	double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;
	/** Computes the statistics (all zero for an empty list). */
	static ErrorStats of(std::vector<double> values);
};

struct AteOptions
{
	/** Max |t_gt - t_est| for two poses to be associated [s] (TUM: 0.02). */
	double maxTimeDifference = 0.02;
	/** Added to the estimate's stamps before association [s]. */
	double timeOffset = 0.0;
};

/** Absolute trajectory error after SE(3) alignment (no scale). */
struct AteResult
{
	/** Associated (gt index, est index) pairs. */
	IndexPairs pairs;
	/** T_WgWe: the estimate's world {We} in the ground truth's world {Wg};
	 * p_Wg = T_alignment * p_We (Horn / Umeyama on positions, no scale). */
	mrpt::poses::CPose3D T_alignment;
	/** Per-pair translational error |t_gt - T_alignment t_est| [m]. */
	std::vector<double> errors;
	/** Statistics of \a errors [m]; stats.rmse is the ATE RMSE. */
	ErrorStats stats;
};

/** ATE as evaluate_ate.py: greedy association (associateGreedy), closed-form
 * least-squares rigid alignment of the estimated positions onto the ground
 * truth positions, then the per-pose position error.
 * Throws std::invalid_argument if either trajectory is empty, if no stamps
 * overlap within maxTimeDifference, or fewer than 3 pairs are found. */
AteResult computeAte(const Trajectory& gt, const Trajectory& est,
                     const AteOptions& opt = {});

struct RpeOptions
{
	/** Time between the two poses of a pair [s] (evaluate_rpe --fixed_delta
	 * --delta 1 --delta_unit s). Errors are reported per this interval, so
	 * with 1 s they are in m/s and deg/s. */
	double delta = 1.0;
	/** Added to the estimate's stamps before looking up the ground truth. */
	double timeOffset = 0.0;
};

/** Relative pose error, evaluate_rpe.py with a fixed delta. */
struct RpeResult
{
	/** (est index i, est index j) pairs used. */
	IndexPairs pairs;
	/** The ground-truth poses of each pair (gt index at i, at j). */
	IndexPairs gtPairs;
	/** Per pair, |translation of E| / delta [m/s] where
	 * E = (G_i^-1 G_j)^-1 (E_i^-1 E_j). */
	std::vector<double> transErrors;
	/** Per pair, rotation angle of E / delta [deg/s]. */
	std::vector<double> rotErrors;
	ErrorStats trans;  ///< [m/s]
	ErrorStats rot;    ///< [deg/s]
};

/** RPE as evaluate_rpe.py (fixed delta in seconds): for each estimated pose
 * i, j is the estimated pose closest in time to t_i + delta (pairs where j is
 * the last pose are dropped, as in the TUM script); the ground-truth poses
 * closest to t_i and t_j must be within twice the median ground-truth period.
 * Throws std::invalid_argument on empty trajectories or fewer than 2 pairs
 * (e.g. no time overlap, or the estimate spans less than delta). */
RpeResult computeRpe(const Trajectory& gt, const Trajectory& est,
                     const RpeOptions& opt = {});

/** What the positions alone say of the RPE's pairs: per pair, the
 * ground truth's displacement against the estimate's, both in the ground
 * truth's world (the estimate's rotated by the ATE's alignment),
 * |dp_gt - R dp_est| / delta [m/s]. When both trajectories' orientations
 * are of the same body frame this equals the RPE's translation error
 * (|t(E)| = |R_Gi^T dp_gt - R_Ei^T dp_est|); far below it, the
 * orientations disagree with the positions. */
ErrorStats displacementErrors(const Trajectory& gt, const Trajectory& est,
                              const RpeResult& rpe, const AteResult& ate,
                              const RpeOptions& opt = {});

/** The rule of bims-eval traj's body-frame warning: the RPE's translation
 * RMSE at least kBodyFrameMinRpe, at least kBodyFrameRatio times the
 * displacements' (the same pairs compared in the aligned world) and, per
 * delta, at least twice the ATE RMSE: the positions agree but the relative
 * motions, read in each trajectory's own body frame, do not. The likely
 * cause: poses of another body than the camera (Bonn's groundtruth.txt is
 * the motion-capture marker's). */
inline constexpr double kBodyFrameRatio = 3.0;
inline constexpr double kBodyFrameMinRpe = 0.01;  ///< [m/s]
bool orientationsDisagreeWithPositions(const ErrorStats& rpeTrans,
                                       const ErrorStats& displacement,
                                       const ErrorStats& ate, double delta);

/** Frame-to-frame figures: what an ATE can hide (one catastrophic frame). */
struct JumpOptions
{
	/** A frame whose translation error exceeds this is counted [m]. */
	double jumpM = 0.03;
};

/** Over consecutive associated poses (k, k+1) in the estimate's time
 * order (the ATE's association): the 1-frame RPE's translation and the
 * speed the estimate implies. */
struct JumpResult
{
	/** Per frame pair, |t(E_k^-1 E_k+1) - t(G_k^-1 G_k+1)| [m] (each
	 * relative motion in its earlier frame; the norm of the translation of
	 * the 1-frame RPE). */
	std::vector<double> transErrors;
	ErrorStats stats;  ///< of \a transErrors [m]
	/** The frame of the largest error: the later pose of its pair. */
	size_t maxEstIndex = 0;
	double maxTime = 0;         ///< its estimate's stamp [s]
	size_t framesOverJump = 0;  ///< frame pairs whose error > jumpM
	double jumpM = 0.03;        ///< the threshold used [m]
	/** Largest |t_est(k+1) - t_est(k)| / (its stamps' difference) [m/s]
	 * (pairs whose stamps do not increase are left out), at the later pose
	 * of its pair, and the reference's over the same pair (its own stamps). */
	double maxSpeed = 0, refSpeedAtMax = 0;
	size_t maxSpeedEstIndex = 0;
	double maxSpeedTime = 0;  ///< [s]
};

/** The frame-to-frame figures over the associated \a pairs (gt index, est
 * index) of computeAte. Throws std::invalid_argument with fewer than 2
 * pairs. */
JumpResult computeJumps(const Trajectory& gt, const Trajectory& est,
                        const IndexPairs& pairs, const JumpOptions& opt = {});

/** Both metrics plus the inputs' sizes, for reports. */
struct TrajectoryReport
{
	std::string gtPath, estPath;
	size_t gtPoses = 0, estPoses = 0;
	AteOptions ateOptions;
	RpeOptions rpeOptions;
	AteResult ate;
	RpeResult rpe;
	JumpResult jumps;
	/** A JSON object (summaries only, no per-pair arrays). */
	Json toJson() const;
};

/** The estimate's positions mapped into the ground-truth world with
 * T_alignment (for plots). */
Trajectory alignTrajectory(const Trajectory& est,
                           const mrpt::poses::CPose3D& T);

}  // namespace bims::eval
