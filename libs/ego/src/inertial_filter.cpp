#include <bims/ego/inertial_filter.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <vector>

namespace bims::ego
{
namespace
{
using Mat12 = Eigen::Matrix<double, 12, 12>;
// blocks of the error state
constexpr int kP = 0, kV = 3, kB = 6, kG = 9;

/** The chi-square quantile of \a dof degrees of freedom at the probability
 * of \a sigma standard deviations of a normal variable (Wilson-Hilferty).
 */
double chiSquareGate(int dof, double sigma)
{
	const double k = dof, c = 2 / (9 * k);
	const double x = 1 - c + sigma * std::sqrt(c);
	return k * x * x * x;
}
/** \a delta without its components along the degenerate directions of
 * \a d (solution remapping, Zhang & Singh): the alignment measured nothing
 * there, whatever its solver did. */
Eigen::Vector3d remapped(Eigen::Vector3d delta, const Degeneracy& d)
{
	for (int i = 0; i < d.count; i++)
	{
		const Eigen::Vector3d n = d.directions.col(i);
		delta -= n * n.dot(delta);
	}
	return delta;
}
}  // namespace

Degeneracy analyseDegeneracy(const Eigen::Matrix3d& Lambda, double sigma_m,
                             double ratio)
{
	Degeneracy d;
	const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(
	    0.5 * (Lambda + Lambda.transpose()));
	d.eigenvalues = es.eigenvalues();
	d.directions = es.eigenvectors();
	// information below 1 / sigma^2: the direction is known worse than
	// sigma; or below \a ratio of the best-known direction's
	const double minInfo =
	    std::max(1 / (sigma_m * sigma_m), ratio * d.eigenvalues[2]);
	d.count = 0;
	for (int i = 0; i < 3; i++)
		if (!(d.eigenvalues[i] >= minInfo)) ++d.count;
	return d;
}

Eigen::Matrix3d levellingRotation(const Eigen::Vector3d& g_W)
{
	if (!(g_W.norm() > 0)) return Eigen::Matrix3d::Identity();
	return Eigen::Quaterniond::FromTwoVectors(g_W.normalized(),
	                                          Eigen::Vector3d(0, 0, -1))
	    .toRotationMatrix();
}

InertialFilter::InertialFilter(const InertialParams& p) : p_(p)
{
}

void InertialFilter::addAccel(double t, const Eigen::Vector3d& f_I)
{
	if (!acc_.empty() && !(t > acc_.back().t)) return;
	if (!f_I.allFinite()) return;
	acc_.push_back({t, f_I});
}

void InertialFilter::initialize(double t, const Eigen::Vector3d& p_WC)
{
	x_ = InertialState{};
	x_.t = t;
	x_.p_WC = p_WC;
	// The odometry's world is the attitude filter's: gravity straight down,
	// up to the filter's tilt error (init_gravity_sigma).
	x_.g_W = Eigen::Vector3d(0, 0, -9.80665);
	auto& P = x_.P;
	P.setZero();
	P.block<3, 3>(kV, kV).diagonal().setConstant(p_.init_velocity_sigma *
	                                             p_.init_velocity_sigma);
	P.block<3, 3>(kB, kB).diagonal().setConstant(p_.init_acc_bias_sigma *
	                                             p_.init_acc_bias_sigma);
	P.block<3, 3>(kG, kG).diagonal().setConstant(p_.init_gravity_sigma *
	                                             p_.init_gravity_sigma);
	init_ = true;
	// samples before t are not needed again (one kept for interpolation)
	while (acc_.size() > 1 && acc_[1].t <= t) acc_.pop_front();
}

void InertialFilter::step(double dt, const std::optional<Eigen::Matrix3d>& R,
                          const std::optional<Eigen::Vector3d>& f_I)
{
	if (!(dt > 0)) return;
	const bool inertial = R && f_I;
	Eigen::Vector3d a = Eigen::Vector3d::Zero();
	if (inertial) a = *R * (*f_I - x_.b_a) + x_.g_W;
	x_.p_WC += x_.v_W * dt + 0.5 * a * dt * dt;
	x_.v_W += a * dt;
	x_.t += dt;
	// Error-state transition: dp' = dp + dv dt + dt^2/2 (-R db + dg),
	// dv' = dv + dt (-R db + dg); without the accelerometer the
	// acceleration is not modelled by b_a and g (no coupling).
	Mat12 F = Mat12::Identity();
	F.block<3, 3>(kP, kV).diagonal().setConstant(dt);
	if (inertial)
	{
		F.block<3, 3>(kP, kB) = -0.5 * dt * dt * *R;
		F.block<3, 3>(kP, kG).diagonal().setConstant(0.5 * dt * dt);
		F.block<3, 3>(kV, kB) = -dt * *R;
		F.block<3, 3>(kV, kG).diagonal().setConstant(dt);
	}
	// White acceleration noise of density q: the discrete covariance of
	// (p, v) is q^2 [dt^3/3, dt^2/2; dt^2/2, dt] per axis.
	const double q = inertial ? p_.acc_noise_density : p_.motion_accel_density;
	const double q2 = q * q;
	Mat12 Q = Mat12::Zero();
	Q.block<3, 3>(kP, kP).diagonal().setConstant(q2 * dt * dt * dt / 3);
	Q.block<3, 3>(kP, kV).diagonal().setConstant(q2 * dt * dt / 2);
	Q.block<3, 3>(kV, kP).diagonal().setConstant(q2 * dt * dt / 2);
	Q.block<3, 3>(kV, kV).diagonal().setConstant(q2 * dt);
	Q.block<3, 3>(kB, kB).diagonal().setConstant(p_.acc_bias_walk *
	                                             p_.acc_bias_walk * dt);
	Q.block<3, 3>(kG, kG).diagonal().setConstant(p_.gravity_walk *
	                                             p_.gravity_walk * dt);
	x_.P = F * x_.P * F.transpose() + Q;
	x_.P = 0.5 * (x_.P + x_.P.transpose()).eval();
}

InertialPropagation InertialFilter::propagate(double t, const RotationAt& R_WI)
{
	InertialPropagation out;
	if (!init_ || !(t > x_.t)) return out;
	const double t0 = x_.t;
	// The specific force between consecutive samples is linear in time; a
	// step ends at each sample inside (t0, t) and at t. A stretch with no
	// sample within max_gap of either end is under the motion prior.
	const double maxGap = 0.1;
	auto saturated = [&](const Eigen::Vector3d& f)
	{ return f.cwiseAbs().maxCoeff() >= p_.accel_range_ms2; };
	// the force at tau, linear between the samples around it; none where
	// no sample is near, or where one of them is saturated
	bool clipped = false;
	auto forceAt = [&](double tau) -> std::optional<Eigen::Vector3d>
	{
		clipped = false;
		if (acc_.empty()) return std::nullopt;
		auto it =
		    std::lower_bound(acc_.begin(), acc_.end(), tau,
		                     [](const Accel& s, double x) { return s.t < x; });
		auto usable = [&](const Accel& s)
		{
			clipped = clipped || saturated(s.f);
			return !saturated(s.f);
		};
		if (it == acc_.end() || it == acc_.begin())
		{
			// before the first or after the last sample: the nearest one
			// holds for half the gap
			const Accel& s = it == acc_.end() ? acc_.back() : acc_.front();
			if (std::abs(s.t - tau) > 0.5 * maxGap || !usable(s))
				return std::nullopt;
			return s.f;
		}
		const Accel& b = *it;
		const Accel& a = *(it - 1);
		if (b.t - a.t > maxGap) return std::nullopt;
		const bool ok = usable(a) & usable(b);
		if (!ok) return std::nullopt;
		const double w = (tau - a.t) / (b.t - a.t);
		return ((1 - w) * a.f + w * b.f).eval();
	};
	std::vector<double> knots{t0};
	for (const Accel& s : acc_)
		if (s.t > t0 && s.t < t) knots.push_back(s.t);
	knots.push_back(t);
	for (size_t k = 0; k + 1 < knots.size(); k++)
	{
		const double a = knots[k], b = knots[k + 1], dt = b - a;
		if (!(dt > 0)) continue;
		const double mid = 0.5 * (a + b);
		const std::optional<Eigen::Vector3d> f = forceAt(mid);
		out.saturated = out.saturated || clipped;
		std::optional<Eigen::Matrix3d> R;
		if (f) R = R_WI(mid);
		step(dt, R, f);
		if (f && R)
		{
			out.covered_s += dt;
			++out.samples;
		}
		else
			out.prior_s += dt;
	}
	x_.t = t;
	// keep one sample before t for the next interval's interpolation
	while (acc_.size() > 1 && acc_[1].t <= t) acc_.pop_front();
	return out;
}

Eigen::Matrix3d InertialFilter::positionInformation() const
{
	return x_.P.block<3, 3>(kP, kP).ldlt().solve(Eigen::Matrix3d::Identity());
}

InertialUpdate InertialFilter::check(const Eigen::Vector3d& p_WC,
                                     const Eigen::Matrix3d& Lambda_W) const
{
	InertialUpdate u;
	u.degeneracy =
	    analyseDegeneracy(Lambda_W, p_.degenerate_sigma_m, p_.degenerate_ratio);
	if (!init_) return u;
	// The alignment's MAP moved the position by delta from the prediction.
	// Its innovation as a measurement of the position (information Lambda):
	// nu = (I + Lambda^-1 P^-1) delta, covariance P + Lambda^-1, over the
	// directions Lambda constrains (the others carry no measurement).
	const Degeneracy& d = u.degeneracy;
	const Eigen::Vector3d delta = remapped(p_WC - x_.p_WC, d);
	const int dof = 3 - d.count;
	u.dof = dof;
	u.accepted = true;
	if (dof == 0) return u;
	// the constrained directions: the last dof eigenvectors
	const Eigen::MatrixXd V = d.directions.rightCols(dof);
	const Eigen::VectorXd lam = d.eigenvalues.tail(dof);
	const Eigen::Vector3d Pid = positionInformation() * delta;
	const Eigen::VectorXd nu =
	    V.transpose() * delta +
	    lam.cwiseInverse().asDiagonal() * (V.transpose() * Pid);
	Eigen::MatrixXd S = V.transpose() * x_.P.block<3, 3>(kP, kP) * V;
	S.diagonal() += lam.cwiseInverse();
	u.nis = nu.dot(S.ldlt().solve(nu));
	u.accepted = u.nis <= chiSquareGate(dof, p_.gate_sigma);
	return u;
}

InertialUpdate InertialFilter::update(const Eigen::Vector3d& p_WC,
                                      const Eigen::Matrix3d& Lambda_W)
{
	InertialUpdate u = check(p_WC, Lambda_W);
	if (!init_ || !u.accepted)
	{
		u.accepted = false;
		return u;
	}
	const Eigen::Matrix3d Ipp = positionInformation();
	// Solution remapping (Zhang & Singh): along the degenerate directions
	// the alignment measured nothing, so whatever its solver did there is
	// dropped and the prediction stands.
	const Eigen::Vector3d delta = remapped(p_WC - x_.p_WC, u.degeneracy);
	// The posterior of the position: the MAP, information Ipp + Lambda.
	// The other states follow by conditioning on it (their correlation with
	// the position): x_o += G (p - p_pred), G = P_op P_pp^-1.
	// the information the alignment has along what it constrains only
	Eigen::Matrix3d Lambda = Lambda_W;
	if (u.degeneracy.count > 0)
	{
		const Degeneracy& d = u.degeneracy;
		const int dof = 3 - d.count;
		const Eigen::MatrixXd V = d.directions.rightCols(dof);
		Lambda = V * d.eigenvalues.tail(dof).asDiagonal() * V.transpose();
	}
	const Eigen::Matrix3d Sigma =
	    (Ipp + Lambda).ldlt().solve(Eigen::Matrix3d::Identity());
	const Eigen::Matrix<double, 9, 3> G = x_.P.block<9, 3>(3, kP) * Ipp;
	const Eigen::Matrix<double, 9, 1> dx = G * delta;
	x_.v_W += dx.segment<3>(0);
	x_.b_a += dx.segment<3>(3);
	x_.g_W += dx.segment<3>(6);
	x_.p_WC += delta;
	Mat12 P = Mat12::Zero();
	const Eigen::Matrix<double, 9, 9> Poo = x_.P.block<9, 9>(3, 3);
	P.block<3, 3>(kP, kP) = Sigma;
	P.block<9, 3>(3, kP) = G * Sigma;
	P.block<3, 9>(kP, 3) = (G * Sigma).transpose();
	P.block<9, 9>(3, 3) =
	    Poo - G * x_.P.block<3, 9>(kP, 3) + G * Sigma * G.transpose();
	x_.P = 0.5 * (P + P.transpose());
	u.accepted = true;
	return u;
}

void InertialFilter::resetPosition(const Eigen::Vector3d& p_WC, double sigma_m)
{
	x_.p_WC = p_WC;
	x_.P.block<3, 3>(kP, kP).diagonal().array() += sigma_m * sigma_m;
}

}  // namespace bims::ego
