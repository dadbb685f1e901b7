#include <bims/common/config.h>
#include <bims/common/frames.h>
#include <bims/sim/motion.h>
#include "ini_vector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bims::sim
{
using detail::kDeg;
using detail::stdv;
using detail::vec3;
namespace
{

/** value, 1st and 2nd derivative of A(sin(wt+a)-sin a) +
 * 0.35A(sin(1.73wt+b)-sin b). */
void channel(double A, double fHz, int ch, double t, double& f, double& d1,
             double& d2)
{
	const double a = 0.9 + 1.3 * ch, b = 2.1 + 0.7 * ch;  // fixed phases
	const double w1 = 2 * M_PI * fHz, w2 = 1.73 * w1, A2 = 0.35 * A;
	f = A * (std::sin(w1 * t + a) - std::sin(a)) +
	    A2 * (std::sin(w2 * t + b) - std::sin(b));
	d1 = A * w1 * std::cos(w1 * t + a) + A2 * w2 * std::cos(w2 * t + b);
	d2 = -A * w1 * w1 * std::sin(w1 * t + a) -
	     A2 * w2 * w2 * std::sin(w2 * t + b);
}

/** The motion's own time s(t) and its first two derivatives
 * (HandheldMotionParams::startFromRestS). */
struct EasedTime
{
	double s, ds, dds;
};
EasedTime easedTime(double tau, double t)
{
	if (tau <= 0) return {t, 1, 0};
	if (t <= 0) return {0, 0, 0};  // held still before the start
	const double e = std::exp(-t / tau);
	return {t - tau * (1 - e), 1 - e, e / tau};
}
/** A channel's derivatives in s turned into derivatives in t (the chain
 * rule); none when s = t (the values stay those of the plain time). */
void chainRule(const EasedTime& w, double& d1, double& d2)
{
	if (w.ds == 1 && w.dds == 0) return;
	d2 = d2 * w.ds * w.ds + d1 * w.dds;
	d1 *= w.ds;
}

Eigen::Matrix3d R_SC_eigen()
{
	Eigen::Matrix3d R;
	// columns: optical x,y,z axes expressed in {S}
	R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
	return R;
}
}  // namespace

void HandheldMotionParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	ConfigSection s(cfg, section);
	position = vec3(s.getDoubles("position", stdv(position), 3, -100, 100));
	yprDeg = vec3(s.getDoubles("ypr_deg", stdv(yprDeg), 3, -360, 360));
	posAmplitude =
	    vec3(s.getDoubles("pos_amplitude", stdv(posAmplitude), 3, 0, 10));
	posFreqHz = vec3(s.getDoubles("pos_freq_hz", stdv(posFreqHz), 3, 0, 20));
	rotAmplitudeDeg = vec3(
	    s.getDoubles("rot_amplitude_deg", stdv(rotAmplitudeDeg), 3, 0, 80));
	rotFreqHz = vec3(s.getDoubles("rot_freq_hz", stdv(rotFreqHz), 3, 0, 20));
	velocity = vec3(s.getDoubles("velocity", stdv(velocity), 3, -5, 5));
	startFromRestS = s.getDouble("start_from_rest_s", startFromRestS, 0, 100);
	s.finish();
}

Kinematics HandheldMotion::at(double t) const
{
	Kinematics k;
	const EasedTime w = easedTime(p_.startFromRestS, t);
	double f, d1, d2;
	for (int i = 0; i < 3; i++)
	{
		channel(p_.posAmplitude[i], p_.posFreqHz[i], i, w.s, f, d1, d2);
		if (p_.velocity[i] != 0)
		{
			f += p_.velocity[i] * w.s;
			d1 += p_.velocity[i];
		}
		chainRule(w, d1, d2);
		k.p_WC[i] = p_.position[i] + f;
		k.v_W[i] = d1;
		k.a_W[i] = d2;
	}
	double ang[3], rate[3];
	for (int i = 0; i < 3; i++)
	{
		channel(p_.rotAmplitudeDeg[i] * kDeg, p_.rotFreqHz[i], 3 + i, w.s, f,
		        d1, d2);
		chainRule(w, d1, d2);
		ang[i] = p_.yprDeg[i] * kDeg + f;
		rate[i] = d1;
	}
	const Eigen::Matrix3d Rz =
	    Eigen::AngleAxisd(ang[0], Eigen::Vector3d::UnitZ()).toRotationMatrix();
	const Eigen::Matrix3d Ry =
	    Eigen::AngleAxisd(ang[1], Eigen::Vector3d::UnitY()).toRotationMatrix();
	const Eigen::Matrix3d Rx =
	    Eigen::AngleAxisd(ang[2], Eigen::Vector3d::UnitX()).toRotationMatrix();
	const Eigen::Matrix3d R_WS = Rz * Ry * Rx;
	// Body rate of R = Rz Ry Rx: w_S = Rx' Ry' (0,0,yaw') + Rx' (0,pitch',0) +
	// (roll',0,0)
	const Eigen::Vector3d w_S =
	    Rx.transpose() * Ry.transpose() * Eigen::Vector3d(0, 0, rate[0]) +
	    Rx.transpose() * Eigen::Vector3d(0, rate[1], 0) +
	    Eigen::Vector3d(rate[2], 0, 0);
	static const Eigen::Matrix3d R_SC = R_SC_eigen();
	k.R_WC = R_WS * R_SC;
	k.omega_C = R_SC.transpose() * w_S;
	return k;
}

// ---------------------------------------------------------------------------
SplineMotion::SplineMotion(const Trajectory& traj)
{
	const size_t n = traj.size();
	if (n < 4)
		throw std::invalid_argument(
		    "SplineMotion: need at least 4 poses, got " + std::to_string(n));
	t_.resize(n);
	for (auto& y : y_) y.resize(n);
	Eigen::Quaterniond prev(1, 0, 0, 0);
	for (size_t i = 0; i < n; i++)
	{
		t_[i] = traj[i].t;
		if (i > 0 && !(t_[i] > t_[i - 1]))
			throw std::invalid_argument(
			    "SplineMotion: timestamps must increase (pose " +
			    std::to_string(i) + ")");
		const auto& T = traj[i].T_WC;
		Eigen::Matrix3d R;
		for (int r = 0; r < 3; r++)
			for (int c = 0; c < 3; c++) R(r, c) = T.getRotationMatrix()(r, c);
		Eigen::Quaterniond q(R);
		q.normalize();
		if (i > 0 && q.coeffs().dot(prev.coeffs()) < 0)
			q.coeffs() *= -1;  // unwrap
		prev = q;
		y_[0][i] = T.x();
		y_[1][i] = T.y();
		y_[2][i] = T.z();
		y_[3][i] = q.w();
		y_[4][i] = q.x();
		y_[5][i] = q.y();
		y_[6][i] = q.z();
	}
	// Natural cubic spline second derivatives (tridiagonal solve per channel).
	for (int ch = 0; ch < 7; ch++)
	{
		auto& y = y_[ch];
		auto& m = m_[ch];
		m.assign(n, 0.0);
		std::vector<double> c(n, 0.0), d(n, 0.0);
		for (size_t i = 1; i + 1 < n; i++)
		{
			const double h0 = t_[i] - t_[i - 1], h1 = t_[i + 1] - t_[i];
			const double a = h0, b = 2 * (h0 + h1), cc = h1;
			const double r =
			    6 * ((y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0);
			const double denom = b - a * c[i - 1];
			c[i] = cc / denom;
			d[i] = (r - a * d[i - 1]) / denom;
		}
		for (size_t i = n - 2; i >= 1; i--)
		{
			m[i] = d[i] - c[i] * m[i + 1];
			if (i == 1) break;
		}
	}
}

void SplineMotion::eval(int ch, size_t i, double tt, double& f, double& d1,
                        double& d2) const
{
	const auto& y = y_[ch];
	const auto& m = m_[ch];
	const double h = t_[i + 1] - t_[i];
	const double A = (t_[i + 1] - tt) / h, B = (tt - t_[i]) / h;
	f = A * y[i] + B * y[i + 1] +
	    ((A * A * A - A) * m[i] + (B * B * B - B) * m[i + 1]) * h * h / 6;
	d1 = (y[i + 1] - y[i]) / h - (3 * A * A - 1) / 6 * h * m[i] +
	     (3 * B * B - 1) / 6 * h * m[i + 1];
	d2 = A * m[i] + B * m[i + 1];
}

Kinematics SplineMotion::at(double t) const
{
	const double tc = std::clamp(t, t_.front(), t_.back());
	size_t i = size_t(std::upper_bound(t_.begin(), t_.end(), tc) - t_.begin());
	i = std::clamp<size_t>(i, 1, t_.size() - 1) - 1;
	Kinematics k;
	double f[7], d1[7], d2[7];
	for (int ch = 0; ch < 7; ch++) eval(ch, i, tc, f[ch], d1[ch], d2[ch]);
	k.p_WC = {f[0], f[1], f[2]};
	k.v_W = {d1[0], d1[1], d1[2]};
	k.a_W = {d2[0], d2[1], d2[2]};
	// q = s/|s|, dq = (ds - q (q.ds)) / |s|; omega_body = 2 vec(conj(q) * dq)
	Eigen::Vector4d s(f[3], f[4], f[5], f[6]), ds(d1[3], d1[4], d1[5], d1[6]);
	const double ns = s.norm();
	const Eigen::Vector4d q4 = s / ns;
	const Eigen::Vector4d dq4 = (ds - q4 * q4.dot(ds)) / ns;
	const Eigen::Quaterniond q(q4[0], q4[1], q4[2], q4[3]);
	const Eigen::Quaterniond dq(dq4[0], dq4[1], dq4[2], dq4[3]);
	const Eigen::Quaterniond w = q.conjugate() * dq;
	k.R_WC = q.toRotationMatrix();
	k.omega_C = 2.0 * w.vec();
	return k;
}

}  // namespace bims::sim
