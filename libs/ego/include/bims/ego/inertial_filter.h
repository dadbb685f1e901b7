// InertialFilter: the translation of the camera carried by the accelerometer
// between depth frames and corrected by the keyframe alignment (issue 52,
// docs/ego.md "Depth-inertial translation").
//
// An error-state Kalman filter over the states the depth cannot see between
// two frames: position p_WC [m], velocity v_W [m/s], the accelerometer's bias
// b_a in {I} [m/s^2] and gravity g_W in the odometry's world [m/s^2] (a
// 3-vector: the world's vertical is the attitude filter's, off by its tilt
// error until the attitude blend has removed it). The rotation R_WI is not a
// state: the gyro and the keyframe alignment measure it to a fraction of a
// degree (docs/ego.md), and the filter takes it as given at every IMU sample.
//
//   propagate(t, R_WI): the specific force f_I of every sample between the
//     state's time and t, a_W = R_WI (f_I - b_a) + g_W, integrated (constant
//     acceleration between the samples' midpoints); where no sample covers an
//     interval (an IMU gap, an IMU that stopped, stamps on another clock) the
//     motion prior stands instead: constant velocity with a hand-held
//     camera's random acceleration (motion_accel_density).
//   update(p, Lambda): the position the alignment found with the prediction
//     as its prior (an iterated update: the alignment is the Gauss-Newton of
//     the measurement and the prior together) and the information the depth
//     alone gives about it (Lambda, 3x3, world frame). Directions where Lambda
//     is weak (the geometry does not constrain them) keep the prediction; an
//     alignment whose innovation is beyond the chi-square gate is refused.
//
// No threads, no I/O. The math is tested against a simulated trajectory
// (test_inertial_filter.cpp).
#pragma once

#include <bims/ego/params.h>

#include <Eigen/Core>

#include <deque>
#include <functional>
#include <optional>

namespace bims::ego
{
/** What the depth alignment's information says of one frame's position. */
struct Degeneracy
{
	/** Eigenvalues of the position information, ascending [1/m^2]. */
	Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();
	/** Their eigenvectors (columns, world frame). */
	Eigen::Matrix3d directions = Eigen::Matrix3d::Identity();
	/** Directions the depth pins to worse than degenerate_sigma_m (0-3). */
	int count = 3;
};

/** Eigen-analysis of the position information \a Lambda (3x3, symmetric
 * [1/m^2]) (Zhang & Singh, ICRA 2016): the directions whose standard
 * deviation 1/sqrt(eigenvalue) exceeds \a sigma_m, or whose eigenvalue is
 * below \a ratio of the largest, are degenerate. */
Degeneracy analyseDegeneracy(const Eigen::Matrix3d& Lambda, double sigma_m,
                             double ratio = 0);

/** The smallest rotation that turns \a g_W (gravity in a world whose z
 * should point up) to straight down: R_W'W, with which R_W'C = R_W'W R_WC
 * is the attitude levelled by the estimated gravity. Identity for a zero
 * vector. */
Eigen::Matrix3d levellingRotation(const Eigen::Vector3d& g_W);

/** The filter's state and covariance (error state [dp, dv, db_a, dg]). */
struct InertialState
{
	double t = 0;  ///< IMU clock [s]
	Eigen::Vector3d p_WC = Eigen::Vector3d::Zero();
	Eigen::Vector3d v_W = Eigen::Vector3d::Zero();
	Eigen::Vector3d b_a = Eigen::Vector3d::Zero();  ///< in {I}
	Eigen::Vector3d g_W = Eigen::Vector3d(0, 0, -9.80665);
	Eigen::Matrix<double, 12, 12> P = Eigen::Matrix<double, 12, 12>::Zero();
};

/** What propagate() did over one interval. */
struct InertialPropagation
{
	int samples = 0;         ///< steps integrated with the accelerometer
	double covered_s = 0;    ///< time integrated with the accelerometer [s]
	double prior_s = 0;      ///< time under the motion prior (no samples) [s]
	bool saturated = false;  ///< a sample beyond accel_range_ms2 was left out
};

/** What update() did with one alignment. */
struct InertialUpdate
{
	bool accepted = false;  ///< the position was taken
	double nis = 0;         ///< normalised innovation squared
	int dof = 0;            ///< its degrees of freedom (constrained dirs)
	Degeneracy degeneracy;  ///< of the alignment's information
};

class InertialFilter
{
 public:
	explicit InertialFilter(const InertialParams& p);

	/** Adds an accelerometer sample (specific force in {I} [m/s^2], IMU
	 * clock [s]); samples must come in time order (others are ignored). */
	void addAccel(double t, const Eigen::Vector3d& f_I);

	/** Starts the filter at IMU time \a t, position \a p_WC, velocity 0
	 * (init_velocity_sigma), no bias (init_acc_bias_sigma), gravity
	 * straight down the world's z (init_gravity_sigma: the world's vertical
	 * is the attitude filter's). */
	void initialize(double t, const Eigen::Vector3d& p_WC);
	bool initialized() const { return init_; }

	/** Rotation R_WI at an IMU time, or nullopt where unknown. */
	using RotationAt = std::function<std::optional<Eigen::Matrix3d>(double)>;

	/** Propagates the state to IMU time \a t (> state time). */
	InertialPropagation propagate(double t, const RotationAt& R_WI);

	/** The position information of the prediction (P_pp^-1, world). */
	Eigen::Matrix3d positionInformation() const;

	/** What update() would do with \a p_WC and \a Lambda_W (the gate's
	 * verdict, the innovation, the degeneracy), changing nothing. */
	InertialUpdate check(const Eigen::Vector3d& p_WC,
	                     const Eigen::Matrix3d& Lambda_W) const;

	/** Fuses the alignment's position \a p_WC (found with the prediction as
	 * its prior) and \a Lambda_W, the information of the depth alone about
	 * it (world frame, [1/m^2]). Refused (state unchanged) when the
	 * innovation over the constrained directions exceeds the gate. */
	InertialUpdate update(const Eigen::Vector3d& p_WC,
	                      const Eigen::Matrix3d& Lambda_W);

	/** Moves the position (and nothing else) to \a p_WC with its current
	 * uncertainty grown by \a sigma_m (a relocalisation, a restart). */
	void resetPosition(const Eigen::Vector3d& p_WC, double sigma_m);

	const InertialState& state() const { return x_; }
	const InertialParams& params() const { return p_; }

 private:
	InertialParams p_;
	bool init_ = false;
	InertialState x_;
	struct Accel
	{
		double t;
		Eigen::Vector3d f;
	};
	std::deque<Accel> acc_;
	/** One constant-acceleration step of length dt (a_W known, or none:
	 * the motion prior), with its covariance. */
	void step(double dt, const std::optional<Eigen::Matrix3d>& R_WI,
	          const std::optional<Eigen::Vector3d>& f_I);
};

}  // namespace bims::ego
