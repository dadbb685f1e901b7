#include <bims/eval/attitude_metrics.h>

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>

namespace bims::eval
{
namespace
{
constexpr double kDeg = 180 / M_PI;

Eigen::Matrix3d rotationOf(const mrpt::poses::CPose3D& T)
{
	return T.getRotationMatrix().asEigen();
}

/** The angle of \a R's twist about the unit axis \a a (swing-twist
 * decomposition) [rad, (-pi, pi]]. */
double twistAbout(const Eigen::Matrix3d& R, const Eigen::Vector3d& a)
{
	const Eigen::Quaterniond q(R);
	const double s = q.vec().dot(a);
	return 2 * std::atan2(s, q.w());
}
}  // namespace

Eigen::Vector3d axisFromName(const std::string& name)
{
	const bool neg = !name.empty() && name[0] == '-';
	const std::string a = neg ? name.substr(1) : name;
	Eigen::Vector3d v;
	if (a == "x")
		v = Eigen::Vector3d::UnitX();
	else if (a == "y")
		v = Eigen::Vector3d::UnitY();
	else if (a == "z")
		v = Eigen::Vector3d::UnitZ();
	else
		throw std::invalid_argument("'" + name +
		                            "' is not an axis (x, y, z, -x, -y, -z)");
	return neg ? Eigen::Vector3d(-v) : v;
}

AttitudeResult computeAttitudeError(const Trajectory& ref,
                                    const Trajectory& est,
                                    const AttitudeOptions& opt)
{
	if (std::abs(opt.upRef.norm() - 1) > 1e-9 ||
	    std::abs(opt.upEst.norm() - 1) > 1e-9)
		throw std::invalid_argument("the up axes must be unit vectors");
	std::vector<double> tr, te;
	for (const auto& p : ref) tr.push_back(p.t);
	const double tStart = est.empty() ? 0 : est.front().t + opt.skip_s;
	std::vector<size_t> estIdx;
	for (size_t j = 0; j < est.size(); j++)
		if (est[j].t >= tStart)
		{
			te.push_back(est[j].t);
			estIdx.push_back(j);
		}
	AttitudeResult r;
	for (const auto& [i, k] : associateGreedy(tr, te, opt.maxTimeDifference))
		r.pairs.push_back({i, estIdx[k]});
	if (r.pairs.size() < 2)
		throw std::invalid_argument(
		    "fewer than 2 poses associate (max time difference " +
		    std::to_string(opt.maxTimeDifference) + " s)");
	const auto& [i0, j0] = r.pairs.front();
	const Eigen::Matrix3d R_WrWe =
	    rotationOf(ref[i0].T_WC) * rotationOf(est[j0].T_WC).transpose();
	double prev = 0;
	for (const auto& [i, j] : r.pairs)
	{
		const Eigen::Matrix3d Rr = rotationOf(ref[i].T_WC);
		const Eigen::Matrix3d Re = rotationOf(est[j].T_WC);
		const Eigen::Vector3d ur = Rr.transpose() * opt.upRef;
		const Eigen::Vector3d ue = Re.transpose() * opt.upEst;
		r.tilt_deg.push_back(std::atan2(ur.cross(ue).norm(), ur.dot(ue)) *
		                     kDeg);
		double h = twistAbout(Rr * (R_WrWe * Re).transpose(), opt.upRef);
		// unwrapped: the nearest to the previous one
		if (!r.heading_deg.empty())
			h += 2 * M_PI * std::round((prev - h) / (2 * M_PI));
		prev = h;
		r.heading_deg.push_back(h * kDeg);
		r.t.push_back(est[j].t);
	}
	r.tilt = ErrorStats::of(r.tilt_deg);
	// least-squares slope of heading over time
	const size_t n = r.t.size();
	double mt = 0, mh = 0;
	for (size_t k = 0; k < n; k++)
	{
		mt += r.t[k] / n;
		mh += r.heading_deg[k] / n;
	}
	double stt = 0, sth = 0;
	for (size_t k = 0; k < n; k++)
	{
		stt += (r.t[k] - mt) * (r.t[k] - mt);
		sth += (r.t[k] - mt) * (r.heading_deg[k] - mh);
		r.heading_max_abs_deg =
		    std::max(r.heading_max_abs_deg, std::abs(r.heading_deg[k]));
	}
	r.heading_drift_deg_min = stt > 0 ? 60 * sth / stt : 0;
	r.span_s = r.t.back() - r.t.front();
	return r;
}

}  // namespace bims::eval
