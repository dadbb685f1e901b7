#include <bims/common/so3.h>
#include <bims/ego/attitude_filter.h>
#include <bims/ego/flags.h>

#include <mrpt/core/Clock.h>

#include <algorithm>
#include <cmath>

namespace bims::ego
{
using mrpt::obs::CObservationIMU;
using namespace mrpt::obs;  // TIMUDataIndex values

AttitudeFilter::AttitudeFilter(const AttitudeParams& p) : p_(p)
{
	if (p_.mag_reference == MagReference::Fixed)
	{
		magRefReady_ = true;
		magNormRef_ = p_.mag_norm;
		magDipRef_ = p_.mag_dip_deg * M_PI / 180;
	}
}

void AttitudeFilter::setState(const Eigen::Quaterniond& q_WI, double t)
{
	q_ = q_WI.normalized();
	qg_ = q_;
	initialized_ = true;
	tInit_ = tLast_ = tAccelOk_ = tMagOk_ = t;
	headingConverged_ = false;
	hist_.clear();
	trimmed_ = false;
	push(t);
}

void AttitudeFilter::push(double t)
{
	hist_.push_back({t, q_, qg_});
	while (hist_.size() > 2 && hist_.back().t - hist_.front().t > p_.history_s)
	{
		hist_.pop_front();
		trimmed_ = true;
	}
}

bool AttitudeFilter::tryInitialize(const ImuSample& s)
{
	if (p_.use_sensor_orientation && s.q_WI)
	{
		setState(*s.q_WI, s.t);
		return true;
	}
	if (!s.hasAcc || s.acc.norm() < 0.5 * p_.gravity) return false;
	const bool useMag = p_.use_magnetometer;
	if (useMag && !s.hasMag) return false;
	// TRIAD: world axes expressed in {I} are the rows of R_WI.
	const Eigen::Vector3d z = s.acc.normalized();  // up (specific force)
	Eigen::Vector3d x;
	if (useMag)
	{
		x = s.mag - s.mag.dot(z) * z;  // horizontal field = north
		if (x.norm() < 1e-6 * s.mag.norm() || s.mag.norm() == 0) return false;
	}
	else
	{
		// No heading reference: keep the IMU's x as close to north as possible.
		x = Eigen::Vector3d::UnitX() - z.x() * z;
		if (x.norm() < 1e-3) x = Eigen::Vector3d::UnitY() - z.y() * z;
	}
	x.normalize();
	const Eigen::Vector3d y = z.cross(x);
	Eigen::Matrix3d R_WI;
	R_WI.row(0) = x;
	R_WI.row(1) = y;
	R_WI.row(2) = z;
	setState(Eigen::Quaterniond(orthonormalize(R_WI)), s.t);
	haveGyro_ = s.hasGyro;
	lastGyro_ = s.gyro;
	return true;
}

bool AttitudeFilter::magUsable(const Eigen::Vector3d& m,
                               const Eigen::Vector3d& up_I)
{
	const double n = m.norm();
	if (n <= 0) return false;
	const double dip = std::asin(std::clamp(-m.dot(up_I) / n, -1.0, 1.0));
	if (!magRefReady_)
	{
		// Learn the reference from the first samples (assumed undisturbed).
		magNormSum_ += n;
		magDipSum_ += dip;
		if (++magRefCount_ >= p_.mag_reference_samples)
		{
			magNormRef_ = magNormSum_ / magRefCount_;
			magDipRef_ = magDipSum_ / magRefCount_;
			magRefReady_ = true;
		}
		return true;
	}
	return std::abs(n / magNormRef_ - 1) <= p_.mag_norm_gate &&
	       std::abs(dip - magDipRef_) <= p_.mag_dip_gate_deg * M_PI / 180;
}

uint32_t AttitudeFilter::add(const ImuSample& s)
{
	if (!std::isfinite(s.t)) return kFlagOutOfOrder;
	if (initialized_ && s.t <= tLast_)
	{
		++stats_.outOfOrder;
		return kFlagOutOfOrder;
	}
	++stats_.samples;
	if (!initialized_)
	{
		tryInitialize(s);
		return 0;
	}
	if (p_.use_sensor_orientation && s.q_WI)
	{
		takeSensorOrientation(s);
		return 0;
	}
	uint32_t flags = 0;
	double dt = s.t - tLast_;
	if (dt > p_.max_gap_s)
	{
		flags |= kFlagImuGap;
		++stats_.gaps;
		dt = p_.max_gap_s;  // do not integrate a rate across a long gap
	}
	const Eigen::Matrix3d R_WI = q_.toRotationMatrix();
	const Eigen::Vector3d up_I = R_WI.transpose().col(2);  // e_z in {I}
	// Innovation: measured x predicted directions (Mahony's omega_mes).
	Eigen::Vector3d e = Eigen::Vector3d::Zero();
	const bool fast = (s.t - tInit_) < p_.init_time_s;
	const bool byAcc = accelInnovation(s, up_I, fast, e, flags);
	const bool byMag = p_.use_magnetometer && s.hasMag &&
	                   magInnovation(s, R_WI, up_I, fast, e, flags);
	integrate(s, R_WI, e, byAcc || byMag, fast, dt, flags);
	return flags;
}

void AttitudeFilter::takeSensorOrientation(const ImuSample& s)
{
	// The sensor's attitude as is; the gyro-only chain still integrates
	// the raw gyro (uncorrected bias) for inter-frame rotations.
	const double dt = s.t - tLast_;
	if (s.hasGyro && haveGyro_ && dt <= p_.max_gap_s)
		qg_ = Eigen::Quaterniond(qg_.toRotationMatrix() *
		                         expSO3(0.5 * (s.gyro + lastGyro_) * dt));
	else
		qg_ = *s.q_WI;
	qg_.normalize();
	if (s.hasGyro)
	{
		lastGyro_ = s.gyro;
		lastRate_ = s.gyro;
		haveGyro_ = true;
	}
	q_ = *s.q_WI;
	tLast_ = s.t;
	push(s.t);
}

bool AttitudeFilter::accelInnovation(const ImuSample& s,
                                     const Eigen::Vector3d& up_I, bool fast,
                                     Eigen::Vector3d& e, uint32_t& flags)
{
	if (!s.hasAcc) return false;
	const double fn = s.acc.norm();
	const Eigen::Vector3d ea = fn > 0
	                               ? Eigen::Vector3d((s.acc / fn).cross(up_I))
	                               : Eigen::Vector3d::Zero();
	// Norm gate, then innovation-angle gate (not while converging, and
	// released when the disagreement persists: then the estimate, not
	// the accelerometer, is wrong).
	bool use = fn > 0 && std::abs(fn - p_.gravity) <= p_.accel_gate;
	const double ang = std::asin(std::min(1.0, ea.norm()));
	if (use && !fast && ang > p_.accel_angle_gate_deg * M_PI / 180 &&
	    s.t - tAccelOk_ < p_.accel_gate_max_s)
		use = false;
	if (!use)
	{
		flags |= kFlagAccelGated;
		++stats_.accelGated;
		return false;
	}
	e += ea;
	if (ang <= p_.accel_angle_gate_deg * M_PI / 180) tAccelOk_ = s.t;
	return true;
}

bool AttitudeFilter::magInnovation(const ImuSample& s,
                                   const Eigen::Matrix3d& R_WI,
                                   const Eigen::Vector3d& up_I, bool fast,
                                   Eigen::Vector3d& e, uint32_t& flags)
{
	const Eigen::Vector3d h_W = R_WI * s.mag;
	// Dip against the measured vertical when the accelerometer is
	// plausible (independent of the estimate), else the estimated one.
	const bool accOk =
	    s.hasAcc && std::abs(s.acc.norm() - p_.gravity) <= p_.accel_gate;
	const Eigen::Vector3d vert =
	    accOk ? Eigen::Vector3d(s.acc.normalized()) : up_I;
	// Heading innovation: angle of the horizontal field from north (+x
	// of {W}). A disturbance that rotates the field horizontally barely
	// changes its norm and dip, so large innovations are gated too
	// (after convergence; released when they persist mag_gate_max_s).
	const double psi = std::atan2(h_W.y(), h_W.x());
	const double gate = p_.mag_heading_gate_deg * M_PI / 180;
	const bool usable =
	    magUsable(s.mag, vert) && std::hypot(h_W.x(), h_W.y()) > 0;
	if (usable && std::abs(psi) <= gate && !fast)
	{
		tMagOk_ = s.t;
		headingConverged_ = true;
	}
	if (!(usable && (fast || !headingConverged_ || std::abs(psi) <= gate ||
	                 s.t - tMagOk_ >= p_.mag_gate_max_s)))
	{
		flags |= kFlagMagGated;
		++stats_.magGated;
		return false;
	}
	// About the vertical only, so a tilted or disturbed field never
	// tilts the estimate; heading gain kp_mag (kp while converging).
	const double ratio = fast ? 1.0 : (p_.kp > 0 ? p_.kp_mag / p_.kp : 0.0);
	e += -psi * ratio * up_I;
	return true;
}

void AttitudeFilter::integrate(const ImuSample& s, const Eigen::Matrix3d& R_WI,
                               const Eigen::Vector3d& e, bool corrected,
                               bool fast, double dt, uint32_t flags)
{
	const double kp = fast ? std::max(p_.kp_init, p_.kp) : p_.kp;
	// Bias integration only near convergence (no wind-up on large errors).
	if (corrected && !fast && e.norm() < 0.05) bias_ -= p_.ki * e * dt;
	// Trapezoidal gyro rate over the interval (zero-order hold if only one).
	Eigen::Vector3d w = Eigen::Vector3d::Zero();
	if (s.hasGyro)
		w = (haveGyro_ && !(flags & kFlagImuGap)) ? 0.5 * (s.gyro + lastGyro_)
		                                          : s.gyro;
	else if (haveGyro_)
		w = lastGyro_;
	lastRate_ = w - bias_;
	const Eigen::Vector3d omega = lastRate_ + kp * e;
	q_ = Eigen::Quaterniond(R_WI * expSO3(omega * dt));
	q_.normalize();
	qg_ = Eigen::Quaterniond(qg_.toRotationMatrix() * expSO3(lastRate_ * dt));
	qg_.normalize();
	if (s.hasGyro)
	{
		lastGyro_ = s.gyro;
		haveGyro_ = true;
	}
	tLast_ = s.t;
	push(s.t);
}

std::optional<Eigen::Quaterniond> AttitudeFilter::attitudeAt(
    double t, uint32_t* flags) const
{
	return lookup(t, flags, false);
}

std::optional<Eigen::Quaterniond> AttitudeFilter::gyroAttitudeAt(
    double t, uint32_t* flags) const
{
	return lookup(t, flags, true);
}

std::optional<Eigen::Quaterniond> AttitudeFilter::lookup(double t,
                                                         uint32_t* flags,
                                                         bool gyroOnly) const
{
	uint32_t f = 0;
	std::optional<Eigen::Quaterniond> out;
	const double eps = 1e-9;
	if (!initialized_ || hist_.empty())
		f |= kFlagImuMissing;
	else if (t < hist_.front().t - eps)
	{
		// Just before the first kept sample (e.g. a recording whose IMU
		// starts right after the first camera frame): hold that sample's
		// attitude within max_gap_s, as after the last one.
		if (hist_.front().t - t <= p_.max_gap_s && !trimmed_)
			out = gyroOnly ? hist_.front().qg : hist_.front().q;
		else
			f |= kFlagImuMissing;
	}
	else if (t >= hist_.back().t)
	{
		const double dt = t - hist_.back().t;
		if (dt > p_.max_gap_s)
			f |= kFlagImuMissing;
		else
			out =
			    Eigen::Quaterniond((gyroOnly ? hist_.back().qg : hist_.back().q)
			                           .toRotationMatrix() *
			                       expSO3(lastRate_ * dt));
	}
	else
	{
		auto it = std::upper_bound(hist_.begin(), hist_.end(), t,
		                           [](double v, const Stamped& s)
		                           { return v < s.t; });
		const Stamped& b = *it;
		const Stamped& a = *(it - 1);
		if (b.t - a.t > p_.max_gap_s) f |= kFlagImuGap;
		const double u = (t - a.t) / (b.t - a.t);
		out = gyroOnly ? a.qg.slerp(u, b.qg) : a.q.slerp(u, b.q);
	}
	if (flags) *flags |= f;
	return out;
}

std::vector<const char*> flagNames(uint32_t flags)
{
	static const std::pair<uint32_t, const char*> names[] = {
	    {kFlagFirstFrame, "first_frame"},
	    {kFlagImuMissing, "imu_missing"},
	    {kFlagImuGap, "imu_gap"},
	    {kFlagTooFewTracks, "too_few_tracks"},
	    {kFlagTooFewInliers, "too_few_inliers"},
	    {kFlagOutOfOrder, "out_of_order"},
	    {kFlagConstVelPrediction, "const_vel_prediction"},
	    {kFlagAccelGated, "accel_gated"},
	    {kFlagMagGated, "mag_gated"},
	    {kFlagBadImage, "bad_image"},
	    {kFlagWorldReanchored, "world_reanchored"},
	    {kFlagAnchored, "anchored"},
	    {kFlagAnchorFailed, "anchor_failed"},
	    {kFlagNewKeyframe, "new_keyframe"},
	    {kFlagAnchorLost, "anchor_lost"},
	    {kFlagMaskIgnored, "mask_ignored"},
	    {kFlagAnchorRelocalised, "anchor_relocalised"},
	    {kFlagImuRejected, "imu_rejected"},
	    {kFlagNoImage, "no_image"},
	    {kFlagMaskVetoed, "mask_vetoed"},
	    {kFlagDegenerate, "degenerate"},
	    {kFlagInertialRejected, "inertial_rejected"},
	    {kFlagInertialPrior, "inertial_prior"},
	    {kFlagAccelSaturated, "accel_saturated"}};
	std::vector<const char*> out;
	for (const auto& [bit, name] : names)
		if (flags & bit) out.push_back(name);
	return out;
}

std::string flagsToString(uint32_t flags)
{
	std::string s;
	for (const char* name : flagNames(flags))
		s += (s.empty() ? "" : "|") + std::string(name);
	return s.empty() ? "ok" : s;
}

}  // namespace bims::ego
