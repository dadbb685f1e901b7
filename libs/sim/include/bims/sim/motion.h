// Camera motion models with analytic derivatives, so that the simulated IMU
// agrees exactly with the ground-truth poses.
#pragma once

#include <bims/io/trajectory.h>
#include <mrpt/config/CConfigFileBase.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace bims::sim
{
/** Kinematic state of the camera {C} (optical frame) at one instant. */
struct Kinematics
{
	Eigen::Matrix3d R_WC =
	    Eigen::Matrix3d::Identity();  ///< orientation of {C} in {W}
	Eigen::Vector3d p_WC =
	    Eigen::Vector3d::Zero();  ///< position of {C} in {W} [m]
	Eigen::Vector3d omega_C =
	    Eigen::Vector3d::Zero();  ///< angular velocity of {C} w.r.t. {W}, in
	                              ///< {C} [rad/s]
	Eigen::Vector3d v_W =
	    Eigen::Vector3d::Zero();  ///< linear velocity in {W} [m/s]
	Eigen::Vector3d a_W =
	    Eigen::Vector3d::Zero();  ///< linear acceleration in {W} [m/s^2]
};

/** A smooth (C2) camera trajectory. */
class MotionModel
{
 public:
	virtual ~MotionModel() = default;
	/** State at time t [s] (the model's own time axis). */
	virtual Kinematics at(double t) const = 0;
	/** Time interval over which the model is defined [s]. */
	virtual double tBegin() const { return -1e300; }
	virtual double tEnd() const { return 1e300; }
};

/** [motion]: hand-held camera motion. Each of the 6 channels (x, y, z, yaw,
 * pitch, roll) is base + A (sin(w s + a) - sin a) + 0.35 A (sin(1.73 w s + b) -
 * sin b) with w = 2 pi f and fixed per-channel phases a, b, plus velocity * s
 * on x, y, z (a walk): smooth, starts at the base pose, derivatives are
 * analytic. s is the time t, or with start_from_rest_s = tau > 0 the eased
 * time s = t - tau (1 - exp(-t / tau)) (s' = 0 at t = 0: the camera starts
 * at rest, velocity and angular rate 0, and is held still before t = 0).
 * The attitude is given for MRPT's scan frame {S} (x forward, y left, z up):
 * yaw/pitch/roll = 0 looks along +x (north), level; R_WC = R_WS(ypr) * R_SC. */
struct HandheldMotionParams
{
	Eigen::Vector3d position{-1.5, 0.0, 1.3};  ///< base position in {W} [m]
	Eigen::Vector3d yprDeg{0, 5,
	                       0};  ///< base yaw, pitch, roll of {S} in {W} [deg]
	Eigen::Vector3d posAmplitude{0.10, 0.15, 0.05};  ///< [m]
	Eigen::Vector3d posFreqHz{0.11, 0.17, 0.23};     ///< [Hz]
	Eigen::Vector3d rotAmplitudeDeg{8, 4,
	                                2};  ///< yaw, pitch, roll amplitudes [deg]
	Eigen::Vector3d rotFreqHz{0.13, 0.19, 0.29};  ///< [Hz]
	Eigen::Vector3d velocity{0, 0, 0};  ///< steady velocity in {W} [m/s]
	double startFromRestS = 0;  ///< ease-in time constant tau [s]; 0 = off
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section);
};

class HandheldMotion : public MotionModel
{
 public:
	explicit HandheldMotion(const HandheldMotionParams& p) : p_(p) {}
	Kinematics at(double t) const override;

 private:
	HandheldMotionParams p_;
};

/** A C2 interpolation of a TUM trajectory (poses T_WC): natural cubic splines
 * on the position and on the (sign-unwrapped) quaternion components,
 * renormalised. Velocity, acceleration and angular velocity come from the
 * spline's analytic derivatives. Defined on [first stamp, last stamp].
 * Throws std::invalid_argument if fewer than 4 poses or non-increasing times.
 */
class SplineMotion : public MotionModel
{
 public:
	explicit SplineMotion(const Trajectory& traj);
	Kinematics at(double t) const override;
	double tBegin() const override { return t_.front(); }
	double tEnd() const override { return t_.back(); }

 private:
	std::vector<double> t_;
	// 7 channels: x y z qw qx qy qz; values and second derivatives at knots
	std::vector<double> y_[7], m_[7];
	void eval(int ch, size_t seg, double tt, double& f, double& d1,
	          double& d2) const;
};

}  // namespace bims::sim
