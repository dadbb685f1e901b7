#include <bims/flow/flow_pose.h>
#include <bims/flow/observed_flow.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <vector>

namespace bims::flow
{
namespace
{
inline bool usable(float z, double zmin, double zmax)
{
	return std::isfinite(z) && z >= zmin && z <= zmax;
}

Eigen::Matrix3d expSO3(const Eigen::Vector3d& w)
{
	const double th = w.norm();
	if (th < 1e-12) return Eigen::Matrix3d::Identity();
	return Eigen::AngleAxisd(th, w / th).toRotationMatrix();
}

double median(std::vector<double> v)
{
	if (v.empty()) return 0;
	const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
	std::nth_element(v.begin(), mid, v.end());
	return *mid;
}

struct Sample
{
	Eigen::Vector3d p;  // current camera frame [m]
	Eigen::Vector2d x;  // observed position in the previous image [px]
};
}  // namespace

Eigen::Matrix<double, 2, 6> flowPoseJacobian(const Eigen::Vector3d& q,
                                             double fx, double fy)
{
	const double iz = 1.0 / q.z();
	Eigen::Matrix<double, 2, 3> Jp;
	Jp << fx * iz, 0, -fx * q.x() * iz * iz, 0, fy * iz, -fy * q.y() * iz * iz;
	Eigen::Matrix<double, 3, 6> Jq;
	Jq << 0, q.z(), -q.y(), 1, 0, 0,  //
	    -q.z(), 0, q.x(), 0, 1, 0,    //
	    q.y(), -q.x(), 0, 0, 0, 1;    // d(q + w x q + d)/d(w, d)
	return Jp * Jq;
}

FlowPoseParams flowPoseParamsFrom(const FlowParams& f)
{
	FlowPoseParams p;
	if (f.refine_pose == RefinePose::None)
		throw std::invalid_argument("flowPoseParamsFrom: refine_pose = none");
	p.mode = f.refine_pose == RefinePose::Translation
	             ? FlowPoseMode::Translation
	             : FlowPoseMode::SE3;
	p.step_px = f.refine_step_px;
	p.iterations = f.refine_iterations;
	p.max_depth_m = f.max_depth_m;
	p.min_texture = f.refine_min_texture;
	return p;
}

cv::Mat depthEdgeMask(const cv::Mat& depth, double rel, int radius)
{
	if (depth.type() != CV_32FC1)
		throw std::invalid_argument("depthEdgeMask: depth must be CV_32FC1");
	if (radius < 1) throw std::invalid_argument("depthEdgeMask: radius < 1");
	cv::Mat out(depth.size(), CV_8UC1, cv::Scalar(0));
	const int offs[8][2] = {{-1, -1}, {0, -1}, {1, -1}, {-1, 0},
	                        {1, 0},   {-1, 1}, {0, 1},  {1, 1}};
	for (int v = 0; v < depth.rows; v++)
	{
		const float* zr = depth.ptr<float>(v);
		auto* o = out.ptr<uint8_t>(v);
		for (int u = 0; u < depth.cols; u++)
		{
			const float z = zr[u];
			if (!(std::isfinite(z) && z > 0)) continue;
			for (const auto& d : offs)
			{
				const int uu = u + d[0] * radius, vv = v + d[1] * radius;
				if (uu < 0 || vv < 0 || uu >= depth.cols || vv >= depth.rows)
					continue;
				const float zn = depth.at<float>(vv, uu);
				if (!(std::isfinite(zn) && zn > 0) ||
				    std::abs(zn - z) > rel * std::min(z, zn))
				{
					o[u] = 255;
					break;
				}
			}
		}
	}
	return out;
}

namespace
{
// refinePoseWithFlow()'s input checks: sizes and types of the images.
void checkFlowPoseInputs(const cv::Mat& observed, const cv::Mat& depth,
                         const FlowPoseParams& p, const cv::Mat* exclude,
                         const cv::Mat* tensor)
{
	if (observed.type() != CV_32FC2 || depth.type() != CV_32FC1 ||
	    observed.size() != depth.size())
		throw std::invalid_argument(
		    "refinePoseWithFlow: need a CV_32FC2 flow and a CV_32FC1 depth of "
		    "one size");
	if (exclude && !exclude->empty() &&
	    (exclude->type() != CV_8UC1 || exclude->size() != depth.size()))
		throw std::invalid_argument(
		    "refinePoseWithFlow: exclusion mask must be CV_8UC1 of the "
		    "depth's size");
	if (tensor && !tensor->empty() &&
	    (tensor->type() != CV_32FC3 || tensor->size() != depth.size()))
		throw std::invalid_argument(
		    "refinePoseWithFlow: structure tensor must be CV_32FC3 of the "
		    "depth's size");
	if (p.step_px < 1 || p.iterations < 1)
		throw std::invalid_argument(
		    "refinePoseWithFlow: step_px and iterations must be >= 1");
}

/** The pinhole intrinsics of the refinement [px]. */
struct FlowPinhole
{
	double fx, fy, cx, cy;
};

/** Whether the depth at (u, v) changes by more than p.edge_rel to a
 * neighbour \a r pixels away (or a neighbour has none). */
bool nearDepthEdge(const cv::Mat& depth, int u, int v, int r, float z,
                   const FlowPoseParams& p)
{
	for (const auto& d :
	     {cv::Point(-r, 0), cv::Point(r, 0), cv::Point(0, -r), cv::Point(0, r)})
	{
		const float zn = depth.at<float>(v + d.y, u + d.x);
		if (!(std::isfinite(zn) && zn > 0) ||
		    std::abs(zn - z) > p.edge_rel * std::min(z, zn))
			return true;
	}
	return false;
}

/** The samples: grid pixels with depth, off depth edges, finite flow (not
 * excluded, textured enough when a structure tensor is given). */
std::vector<Sample> flowPoseSamples(const cv::Mat& observed,
                                    const cv::Mat& depth, const FlowPinhole& K,
                                    const FlowPoseParams& p,
                                    const cv::Mat* exclude,
                                    const cv::Mat* tensor)
{
	const bool useEx = exclude && !exclude->empty();
	const bool useT = tensor && !tensor->empty();
	std::vector<Sample> S;
	S.reserve(static_cast<size_t>((depth.rows / p.step_px + 1) *
	                              (depth.cols / p.step_px + 1)));
	const int r = std::max(1, p.step_px / 2);
	for (int v = r; v + r < depth.rows; v += p.step_px)
		for (int u = r; u + r < depth.cols; u += p.step_px)
		{
			const float z = depth.at<float>(v, u);
			if (!usable(z, p.min_depth_m, p.max_depth_m)) continue;
			if (useEx && exclude->at<uint8_t>(v, u)) continue;
			if (useT && minEigen(tensor->at<cv::Vec3f>(v, u)) < p.min_texture)
				continue;
			const cv::Vec2f f = observed.at<cv::Vec2f>(v, u);
			if (!std::isfinite(f[0]) || !std::isfinite(f[1])) continue;
			if (nearDepthEdge(depth, u, v, r, z, p)) continue;
			Sample s;
			s.p = {(u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z};
			s.x = {u + f[0], v + f[1]};
			S.push_back(s);
		}
	return S;
}

/** The reprojection error [px] of every sample at the pose (R, t) into
 * \a err (one slot per sample; 1e9 behind the camera). */
void flowPoseResiduals(const std::vector<Sample>& S, const Eigen::Matrix3d& R,
                       const Eigen::Vector3d& t, const FlowPinhole& K,
                       std::vector<double>& err)
{
	for (size_t i = 0; i < S.size(); i++)
	{
		const Eigen::Vector3d q = R * S[i].p + t;
		if (q.z() <= 1e-6)
		{
			err[i] = 1e9;
			continue;
		}
		const Eigen::Vector2d pr(K.fx * q.x() / q.z() + K.cx,
		                         K.fy * q.y() / q.z() + K.cy);
		err[i] = (S[i].x - pr).norm();
	}
}

/** The Tukey cut of the errors \a e [px]. */
double flowTukeyCut(const FlowPoseParams& p, const std::vector<double>& e)
{
	return std::clamp(p.tukey_sigmas * 1.4826 * median(e), p.tukey_min_px,
	                  std::max(p.tukey_min_px, p.tukey_max_px));
}

/** One weighted Gauss-Newton step at (R, t) from the errors \a err (Tukey
 * weights below \a cut when \a tukey, else Huber): the increment xi
 * (rotation, translation), or nothing when fewer than p.min_samples
 * samples weigh in or the solve is not finite. */
std::optional<Eigen::Matrix<double, 6, 1>> flowPoseStep(
    const std::vector<Sample>& S, const std::vector<double>& err,
    const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const FlowPinhole& K,
    const FlowPoseParams& p, bool tukey, double cut)
{
	Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
	Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
	size_t nIn = 0;
	for (size_t i = 0; i < S.size(); i++)
	{
		const double e = err[i];
		double w;
		if (tukey)
		{
			if (e >= cut) continue;
			const double a = 1 - (e / cut) * (e / cut);
			w = a * a;
		}
		else
			w = e <= p.huber_px ? 1.0 : p.huber_px / e;
		const Eigen::Vector3d q = R * S[i].p + t;
		if (q.z() <= 1e-6) continue;
		const double iz = 1.0 / q.z();
		const Eigen::Matrix<double, 2, 6> A = flowPoseJacobian(q, K.fx, K.fy);
		const Eigen::Vector2d rr(S[i].x.x() - (K.fx * q.x() * iz + K.cx),
		                         S[i].x.y() - (K.fy * q.y() * iz + K.cy));
		H.noalias() += w * A.transpose() * A;
		g.noalias() += w * A.transpose() * rr;
		nIn++;
	}
	if (nIn < static_cast<size_t>(p.min_samples)) return std::nullopt;
	Eigen::Matrix<double, 6, 1> xi = Eigen::Matrix<double, 6, 1>::Zero();
	// Levenberg damping keeps the weakly observed directions (e.g. the
	// translation along the optical axis of a far scene) in place.
	for (int k = 0; k < 6; k++) H(k, k) *= 1.0 + 1e-6;
	if (p.mode == FlowPoseMode::SE3)
		xi = H.ldlt().solve(g);
	else
		xi.tail<3>() = H.bottomRightCorner<3, 3>().ldlt().solve(g.tail<3>());
	if (!xi.allFinite()) return std::nullopt;
	return xi;
}

/** The pose (R orthonormalised, t). */
mrpt::poses::CPose3D flowPoseOf(const Eigen::Matrix3d& R,
                                const Eigen::Vector3d& t)
{
	Eigen::JacobiSVD<Eigen::Matrix3d> svd(
	    R, Eigen::ComputeFullU | Eigen::ComputeFullV);
	const Eigen::Matrix3d Rn = svd.matrixU() * svd.matrixV().transpose();
	mrpt::math::CMatrixDouble33 Ro;
	mrpt::math::CVectorFixedDouble<3> to;
	for (int i = 0; i < 3; i++)
	{
		to[i] = t[i];
		for (int j = 0; j < 3; j++) Ro(i, j) = Rn(i, j);
	}
	return mrpt::poses::CPose3D::FromRotationAndTranslation(Ro, to);
}
}  // namespace

FlowPoseResult refinePoseWithFlow(const cv::Mat& observed, const cv::Mat& depth,
                                  const mrpt::img::TCamera& cam,
                                  const mrpt::poses::CPose3D& init,
                                  const FlowPoseParams& p,
                                  const cv::Mat* exclude, const cv::Mat* tensor)
{
	checkFlowPoseInputs(observed, depth, p, exclude, tensor);
	FlowPoseResult res;
	res.T_CprevC = init;
	const FlowPinhole K{cam.fx(), cam.fy(), cam.cx(), cam.cy()};
	const std::vector<Sample> S =
	    flowPoseSamples(observed, depth, K, p, exclude, tensor);
	res.samples = static_cast<int>(S.size());
	if (res.samples < p.min_samples) return res;

	Eigen::Matrix3d R;
	const auto& Rm = init.getRotationMatrix();
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) R(i, j) = Rm(i, j);
	Eigen::Vector3d t(init.x(), init.y(), init.z());

	std::vector<double> err(S.size());
	flowPoseResiduals(S, R, t, K, err);
	res.median_px_before = median(err);
	double cut = 0;
	for (int it = 0; it < p.iterations; it++)
	{
		const bool tukey = it >= p.iterations / 3;
		if (tukey) cut = flowTukeyCut(p, err);
		const auto xi = flowPoseStep(S, err, R, t, K, p, tukey, cut);
		if (!xi) return res;
		const Eigen::Matrix3d dR = expSO3(xi->head<3>());
		R = dR * R;
		t = dR * t + xi->tail<3>();
		flowPoseResiduals(S, R, t, K, err);
		if (xi->head<3>().norm() < 1e-7 && xi->tail<3>().norm() < 1e-6 && tukey)
			break;
	}
	if (cut <= 0) cut = flowTukeyCut(p, err);
	size_t nIn = 0;
	for (double e : err) nIn += e < cut;
	res.inlier_fraction = static_cast<double>(nIn) / S.size();
	res.median_px_after = median(err);
	res.T_CprevC = flowPoseOf(R, t);
	res.ok = true;
	return res;
}

}  // namespace bims::flow
