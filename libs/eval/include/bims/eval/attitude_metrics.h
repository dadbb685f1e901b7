// Attitude error of an estimated trajectory's rotations against a reference
// (docs/eval.md, "Attitude"): what an IMU's attitude filter is judged by.
//
// Tilt: the angle between the "up" direction seen from the camera by the
// reference, R_WrC^T up_r, and by the estimate, R_WeC^T up_e (each world's
// own up axis: z for bims, y for ARKit). It needs no alignment of the two
// worlds and is what gravity alone makes observable.
// Heading: the two worlds are aligned at the first associated pose
// (R_WrWe = R_WrC(0) R_WeC(0)^T); the heading error at t is the twist about
// up_r of R_WrC(t) (R_WrWe R_WeC(t))^T, unwrapped. Its drift is the slope of
// a least-squares line through it [deg/min]: what a gyro without a
// magnetometer leaves unobserved.
#pragma once

#include <bims/eval/association.h>
#include <bims/eval/trajectory_metrics.h>
#include <bims/io/trajectory.h>

#include <Eigen/Core>

namespace bims::eval
{
struct AttitudeOptions
{
	/** The up axis of each world, as a unit vector ({W} of bims: z; ARKit:
	 * y). */
	Eigen::Vector3d upRef = Eigen::Vector3d::UnitZ();
	Eigen::Vector3d upEst = Eigen::Vector3d::UnitZ();
	/** Max |t_ref - t_est| for two poses to be associated [s]. */
	double maxTimeDifference = 0.02;
	/** Poses of the estimate in its first skip_s seconds are left out (an
	 * attitude filter's convergence) [s]. */
	double skip_s = 0;
};

struct AttitudeResult
{
	IndexPairs pairs;              ///< (ref index, est index) used
	std::vector<double> t;         ///< the estimate's stamps of the pairs [s]
	std::vector<double> tilt_deg;  ///< per pair [deg]
	std::vector<double> heading_deg;  ///< per pair, unwrapped [deg]
	ErrorStats tilt;                  ///< of tilt_deg
	/** Slope of the least-squares line through heading_deg [deg/min]. */
	double heading_drift_deg_min = 0;
	double heading_max_abs_deg = 0;  ///< max |heading_deg|
	double span_s = 0;               ///< time the pairs cover [s]
};

/** Throws std::invalid_argument when fewer than 2 poses associate, or an up
 * axis is not a unit vector. */
AttitudeResult computeAttitudeError(const Trajectory& ref,
                                    const Trajectory& est,
                                    const AttitudeOptions& opt = {});

/** "x", "-y", "z", ... as a unit vector; throws std::invalid_argument
 * naming the value otherwise. */
Eigen::Vector3d axisFromName(const std::string& name);

}  // namespace bims::eval
