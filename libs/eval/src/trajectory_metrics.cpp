#include <bims/eval/trajectory_metrics.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "eigen_pose.h"

namespace bims::eval
{
using detail::fromIso;
using detail::toIso;

ErrorStats ErrorStats::of(std::vector<double> v)
{
	ErrorStats s;
	s.count = v.size();
	if (v.empty()) return s;
	double sum = 0, sum2 = 0;
	for (const double x : v)
	{
		sum += x;
		sum2 += x * x;
	}
	const double n = static_cast<double>(v.size());
	s.mean = sum / n;
	s.rmse = std::sqrt(sum2 / n);
	s.std = std::sqrt(std::max(0.0, sum2 / n - s.mean * s.mean));
	std::sort(v.begin(), v.end());
	s.min = v.front();
	s.max = v.back();
	// numpy.median: mean of the two middle values for even counts.
	const size_t m = v.size() / 2;
	s.median = (v.size() % 2) ? v[m] : 0.5 * (v[m - 1] + v[m]);
	return s;
}

namespace
{
std::vector<double> stamps(const Trajectory& t)
{
	std::vector<double> s;
	s.reserve(t.size());
	for (const auto& p : t) s.push_back(p.t);
	return s;
}
void requireSorted(const Trajectory& t, const char* what)
{
	for (size_t i = 1; i < t.size(); i++)
		if (t[i].t < t[i - 1].t)
			throw std::invalid_argument(std::string(what) +
			                            " trajectory is not sorted by time");
}
/** "[t0, t1] s"; an estimate's with the time offset added to its stamps
 * (what the association compares) when there is one. */
std::string spanText(const Trajectory& t, double offset = 0)
{
	std::ostringstream ss;
	ss.precision(3);
	ss << std::fixed << "[" << t.front().t << ", " << t.back().t << "] s";
	if (offset != 0)
		ss << " ("
		   << "[" << t.front().t + offset << ", " << t.back().t + offset
		   << "] s with the time offset " << std::showpos << offset << " s)";
	return ss.str();
}
}  // namespace

AteResult computeAte(const Trajectory& gt, const Trajectory& est,
                     const AteOptions& opt)
{
	if (gt.empty())
		throw std::invalid_argument("ground-truth trajectory is empty");
	if (est.empty())
		throw std::invalid_argument("estimated trajectory is empty");
	requireSorted(gt, "ground-truth");
	requireSorted(est, "estimated");
	AteResult r;
	r.pairs = associateGreedy(stamps(gt), stamps(est), opt.maxTimeDifference,
	                          opt.timeOffset);
	if (r.pairs.empty())
		throw std::invalid_argument(
		    "no time overlap between ground truth " + spanText(gt) +
		    " and estimate " + spanText(est, opt.timeOffset) + " within " +
		    std::to_string(opt.maxTimeDifference) + " s");
	if (r.pairs.size() < 3)
		throw std::invalid_argument(
		    "only " + std::to_string(r.pairs.size()) +
		    " associated poses; at least 3 are needed for the alignment");
	const auto n = static_cast<Eigen::Index>(r.pairs.size());
	Eigen::Matrix3Xd src(3, n), dst(3, n);
	for (Eigen::Index k = 0; k < n; k++)
	{
		const auto& g = gt[r.pairs[k].first].T_WC;
		const auto& e = est[r.pairs[k].second].T_WC;
		dst.col(k) << g.x(), g.y(), g.z();
		src.col(k) << e.x(), e.y(), e.z();
	}
	// Closed-form least squares rigid alignment (Umeyama 1991 = Horn 1987
	// without scale): dst ~ R src + t.
	Eigen::Isometry3d T(Eigen::umeyama(src, dst, false));
	r.T_alignment = fromIso(T);
	r.errors.resize(r.pairs.size());
	for (Eigen::Index k = 0; k < n; k++)
		r.errors[k] = (T * Eigen::Vector3d(src.col(k)) - dst.col(k)).norm();
	r.stats = ErrorStats::of(r.errors);
	return r;
}

RpeResult computeRpe(const Trajectory& gt, const Trajectory& est,
                     const RpeOptions& opt)
{
	if (gt.empty())
		throw std::invalid_argument("ground-truth trajectory is empty");
	if (est.empty())
		throw std::invalid_argument("estimated trajectory is empty");
	if (!(opt.delta > 0)) throw std::invalid_argument("RPE delta must be > 0");
	requireSorted(gt, "ground-truth");
	requireSorted(est, "estimated");
	const auto sg = stamps(gt), se = stamps(est);

	// Max GT time difference: twice the median GT period (evaluate_rpe.py).
	double gtMaxDiff = 0;
	if (sg.size() >= 2)
	{
		std::vector<double> d;
		for (size_t i = 1; i < sg.size(); i++) d.push_back(sg[i] - sg[i - 1]);
		gtMaxDiff = 2 * ErrorStats::of(d).median;
	}

	RpeResult r;
	for (size_t i = 0; i < se.size(); i++)
	{
		const size_t j = closestIndex(se, se[i] + opt.delta);
		if (j == se.size() - 1) continue;  // as evaluate_rpe.py
		const double t0 = se[i] + opt.timeOffset, t1 = se[j] + opt.timeOffset;
		const size_t g0 = closestIndex(sg, t0), g1 = closestIndex(sg, t1);
		if (std::abs(sg[g0] - t0) > gtMaxDiff ||
		    std::abs(sg[g1] - t1) > gtMaxDiff)
			continue;
		const Eigen::Isometry3d dE =
		    toIso(est[i].T_WC).inverse() * toIso(est[j].T_WC);
		const Eigen::Isometry3d dG =
		    toIso(gt[g0].T_WC).inverse() * toIso(gt[g1].T_WC);
		const Eigen::Isometry3d E = dG.inverse() * dE;
		const double c = std::clamp((E.linear().trace() - 1) / 2, -1.0, 1.0);
		r.pairs.emplace_back(i, j);
		r.gtPairs.emplace_back(g0, g1);
		r.transErrors.push_back(E.translation().norm() / opt.delta);
		r.rotErrors.push_back(std::acos(c) * 180.0 / M_PI / opt.delta);
	}
	if (r.pairs.size() < 2)
	{
		std::ostringstream ss;
		ss << "only " << r.pairs.size() << " RPE pairs (delta " << opt.delta
		   << " s) between ground truth " << spanText(gt) << " and estimate "
		   << spanText(est, opt.timeOffset)
		   << ": no time overlap or the estimate is shorter than delta";
		throw std::invalid_argument(ss.str());
	}
	r.trans = ErrorStats::of(r.transErrors);
	r.rot = ErrorStats::of(r.rotErrors);
	return r;
}

namespace
{
/** |p_b - p_a| / (t_b - t_a), or -1 when the stamps do not increase. */
double speed(const Trajectory& t, size_t a, size_t b)
{
	const double dt = t[b].t - t[a].t;
	const Eigen::Vector3d d =
	    toIso(t[b].T_WC).translation() - toIso(t[a].T_WC).translation();
	return dt > 0 ? d.norm() / dt : -1.0;
}
Eigen::Vector3d relativeTranslation(const Trajectory& t, size_t a, size_t b)
{
	return (toIso(t[a].T_WC).inverse() * toIso(t[b].T_WC)).translation();
}
}  // namespace

JumpResult computeJumps(const Trajectory& gt, const Trajectory& est,
                        const IndexPairs& pairs, const JumpOptions& opt)
{
	if (!(opt.jumpM >= 0) || !std::isfinite(opt.jumpM))
		throw std::invalid_argument("jump threshold must be >= 0 m");
	if (pairs.size() < 2)
		throw std::invalid_argument(
		    "frame-to-frame errors need at least 2 associated poses");
	IndexPairs byEst = pairs;
	std::sort(byEst.begin(), byEst.end(),
	          [](const auto& a, const auto& b) { return a.second < b.second; });
	JumpResult r;
	r.jumpM = opt.jumpM;
	double worst = -1, fastest = -1;
	for (size_t k = 0; k + 1 < byEst.size(); k++)
	{
		const auto [g0, e0] = byEst[k];
		const auto [g1, e1] = byEst[k + 1];
		const double err =
		    (relativeTranslation(est, e0, e1) - relativeTranslation(gt, g0, g1))
		        .norm();
		r.transErrors.push_back(err);
		if (err > opt.jumpM) r.framesOverJump++;
		if (err > worst)
		{
			worst = err;
			r.maxEstIndex = e1;
			r.maxTime = est[e1].t;
		}
		const double v = speed(est, e0, e1);
		if (v > fastest)
		{
			fastest = r.maxSpeed = v;
			r.refSpeedAtMax = std::max(0.0, speed(gt, g0, g1));
			r.maxSpeedEstIndex = e1;
			r.maxSpeedTime = est[e1].t;
		}
	}
	r.stats = ErrorStats::of(r.transErrors);
	return r;
}

ErrorStats displacementErrors(const Trajectory& gt, const Trajectory& est,
                              const RpeResult& rpe, const AteResult& ate,
                              const RpeOptions& opt)
{
	const Eigen::Matrix3d R = toIso(ate.T_alignment).linear();
	std::vector<double> e;
	for (size_t k = 0; k < rpe.pairs.size() && k < rpe.gtPairs.size(); k++)
	{
		const auto [i, j] = rpe.pairs[k];
		const auto [g0, g1] = rpe.gtPairs[k];
		const Eigen::Vector3d dG =
		    toIso(gt[g1].T_WC).translation() - toIso(gt[g0].T_WC).translation();
		const Eigen::Vector3d dE =
		    toIso(est[j].T_WC).translation() - toIso(est[i].T_WC).translation();
		e.push_back((dG - R * dE).norm() / opt.delta);
	}
	return ErrorStats::of(e);
}

bool orientationsDisagreeWithPositions(const ErrorStats& rpeTrans,
                                       const ErrorStats& displacement,
                                       const ErrorStats& ate, double delta)
{
	return rpeTrans.count > 0 && rpeTrans.rmse >= kBodyFrameMinRpe &&
	       rpeTrans.rmse >= kBodyFrameRatio * displacement.rmse &&
	       rpeTrans.rmse * delta >= 2 * ate.rmse;
}

Trajectory alignTrajectory(const Trajectory& est, const mrpt::poses::CPose3D& T)
{
	Trajectory out = est;
	for (auto& p : out) p.T_WC = T + p.T_WC;
	return out;
}

namespace
{
Json statsJson(const ErrorStats& s)
{
	return {{"count", s.count},           {"rmse", jsonNumber(s.rmse)},
	        {"mean", jsonNumber(s.mean)}, {"median", jsonNumber(s.median)},
	        {"std", jsonNumber(s.std)},   {"min", jsonNumber(s.min)},
	        {"max", jsonNumber(s.max)}};
}
}  // namespace

Json TrajectoryReport::toJson() const
{
	const auto& T = ate.T_alignment;
	Json j;
	j["gt"] = gtPath;
	j["est"] = estPath;
	j["gt_poses"] = gtPoses;
	j["est_poses"] = estPoses;
	j["ate"] = {
	    {"max_time_difference_s", jsonNumber(ateOptions.maxTimeDifference)},
	    {"pairs", ate.pairs.size()},
	    {"error_m", statsJson(ate.stats)},
	    {"alignment_T_WgWe",
	     {jsonNumber(T.x()), jsonNumber(T.y()), jsonNumber(T.z()),
	      jsonNumber(T.yaw()), jsonNumber(T.pitch()), jsonNumber(T.roll())}}};
	j["rpe"] = {{"delta_s", jsonNumber(rpeOptions.delta)},
	            {"pairs", rpe.pairs.size()},
	            {"trans_m_per_s", statsJson(rpe.trans)},
	            {"rot_deg_per_s", statsJson(rpe.rot)}};
	j["frame_to_frame"] = {
	    {"frame_pairs", jumps.transErrors.size()},
	    {"trans_err_m", statsJson(jumps.stats)},
	    {"max_frame_trans_err_m", jsonNumber(jumps.stats.max)},
	    {"max_at_t", jsonNumber(jumps.maxTime, 6)},
	    {"max_est_index", jumps.maxEstIndex},
	    {"jump_m", jsonNumber(jumps.jumpM)},
	    {"frames_over_jump", jumps.framesOverJump},
	    {"max_speed_m_per_s", jsonNumber(jumps.maxSpeed)},
	    {"max_speed_at_t", jsonNumber(jumps.maxSpeedTime, 6)},
	    {"max_speed_est_index", jumps.maxSpeedEstIndex},
	    {"ref_speed_at_max_m_per_s", jsonNumber(jumps.refSpeedAtMax)}};
	return j;
}

}  // namespace bims::eval
