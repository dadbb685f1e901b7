#include <bims/common/config.h>
#include <bims/ego/dense_align.h>
#include <bims/ego/depth_correction.h>

#include <Eigen/Cholesky>

#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

namespace bims::ego
{
namespace
{
using Vec = Eigen::Matrix<double, kDepthCorrectionTerms, 1>;
using Mat = Eigen::Matrix<double, kDepthCorrectionTerms, kDepthCorrectionTerms>;

Vec basisVec(double x, double y)
{
	const auto b = depthCorrectionBasis(x, y);
	return Eigen::Map<const Vec>(b.data());
}
}  // namespace

DepthFitResult estimateDepthCorrection(const std::vector<RgbdFrame>& frames,
                                       const std::vector<Eigen::Matrix4d>& T_WC,
                                       const DepthFitOptions& o)
{
	if (frames.size() != T_WC.size())
		throw std::invalid_argument(
		    "estimateDepthCorrection: frames and poses differ in number");
	std::vector<std::pair<int, int>> pairs;
	const int n = static_cast<int>(frames.size());
	for (int i = 0; i < n; i += o.step)
		for (int j = 0; j < n; j += o.step)
			if (std::abs(i - j) >= o.min_gap && std::abs(i - j) <= o.max_gap)
				pairs.emplace_back(i, j);
	if (pairs.empty())
		throw std::invalid_argument(
		    "estimateDepthCorrection: no frame pair " +
		    std::to_string(o.min_gap) + ".." + std::to_string(o.max_gap) +
		    " frames apart (give a longer static stretch)");
	DepthFitResult res;
	res.pairs = static_cast<int>(pairs.size());
	Vec a = Vec::Zero();
	// normals of the reference frames at half size (as the alignment)
	AnchorParams ap;
	ap.finest_level = 1;
	ap.coarsest_level = 1;
	ap.min_depth_m = o.min_depth_m;
	ap.max_depth_m = o.max_depth_m;
	for (int it = 0; it < o.iterations; it++)
	{
		DepthCorrectionParams cur;
		cur.enable = true;
		for (int k = 0; k < kDepthCorrectionTerms; k++)
			cur.coefficients[k] = a[k];
		DepthCorrection corr(cur);
		std::vector<DenseFrame> ref(frames.size());
		std::vector<cv::Mat> depth(frames.size());
		for (int i = 0; i < n; i += o.step)
		{
			if (frames[i].depth.size() != frames[0].depth.size())
				throw std::invalid_argument(
				    "estimateDepthCorrection: frames of different sizes");
			depth[i] = frames[i].depth.clone();
			corr.apply(depth[i], frames[i].K);
			ref[i].build(frames[i].grey, depth[i], frames[i].K, ap);
			ref[i].prepareReference(ap);
		}
		Mat A = Mat::Zero();
		Vec b = Vec::Zero();
		double sum2 = 0;
		size_t count = 0;
		std::mt19937 rng(1);
		for (const auto& [i, j] : pairs)
		{
			const DenseLevel& L = ref[i].levels[1];
			const Eigen::Matrix3d& Kj = frames[j].K;
			const Eigen::Matrix4d T = T_WC[i].inverse() * T_WC[j];
			const Eigen::Matrix3d R = T.block<3, 3>(0, 0);
			const Eigen::Vector3d t = T.block<3, 1>(0, 3);
			const cv::Mat& dj = depth[j];
			std::uniform_int_distribution<int> pu(0, dj.cols - 1),
			    pv(0, dj.rows - 1);
			for (int s = 0; s < o.samples_per_pair; s++)
			{
				const int u = pu(rng), v = pv(rng);
				const double z = dj.at<float>(v, u);
				if (!(z >= o.min_depth_m && z <= o.max_depth_m)) continue;
				const double xj = (u - Kj(0, 2)) / Kj(0, 0),
				             yj = (v - Kj(1, 2)) / Kj(1, 1);
				const Eigen::Vector3d Xj(xj * z, yj * z, z);
				const Eigen::Vector3d RX = R * Xj, Y = RX + t;
				if (Y.z() <= 0) continue;
				const int ui = static_cast<int>(
				              std::lround(L.fx * Y.x() / Y.z() + L.cx)),
				          vi = static_cast<int>(
				              std::lround(L.fy * Y.y() / Y.z() + L.cy));
				if (ui < 0 || vi < 0 || ui >= L.depth.cols ||
				    vi >= L.depth.rows)
					continue;
				const RefPixel& q =
				    L.packed[static_cast<size_t>(vi) * L.depth.cols + ui];
				if (q.z <= 0 || (q.nx == 0 && q.ny == 0 && q.nz == 0)) continue;
				if (std::abs(Y.z() - q.z) > 0.1 * q.z) continue;
				const Eigen::Vector3d nq(q.nx, q.ny, q.nz);
				const double r = nq.dot(Y) - q.d;
				const double xi = (ui - L.cx) / L.fx, yi = (vi - L.cy) / L.fy;
				const Eigen::Vector3d Xi(xi * q.z, yi * q.z, q.z);
				// d r / d a: the current point scales with its factor, the
				// reference point with its own
				const Vec J = nq.dot(RX) * basisVec(xj, yj) -
				              nq.dot(Xi) * basisVec(xi, yi);
				const double w =
				    std::abs(r) <= o.huber_m ? 1 : o.huber_m / std::abs(r);
				A += w * J * J.transpose();
				b += w * J * r;
				sum2 += w * r * r;
				++count;
			}
		}
		if (count < static_cast<size_t>(10 * kDepthCorrectionTerms))
			throw std::invalid_argument(
			    "estimateDepthCorrection: too few overlapping readings (" +
			    std::to_string(count) + ")");
		const double rms = std::sqrt(sum2 / count);
		if (it == 0) res.rms_before_m = rms;
		res.rms_after_m = rms;
		res.residuals = count;
		A.diagonal().array() += 1e-6 * A.diagonal().mean();
		a -= A.ldlt().solve(b);
		if (!a.allFinite())
			throw std::runtime_error("estimateDepthCorrection: diverged");
	}
	res.params.enable = true;
	for (int k = 0; k < kDepthCorrectionTerms; k++)
		res.params.coefficients[k] = a[k];
	const RgbdFrame& f = frames.front();
	const double fx = f.K(0, 0), fy = f.K(1, 1), cx = f.K(0, 2), cy = f.K(1, 2);
	const int W = f.depth.cols, H = f.depth.rows;
	auto at = [&](double u, double v)
	{ return basisVec((u - cx) / fx, (v - cy) / fy).dot(a); };
	res.left = at(0, cy);
	res.right = at(W - 1, cy);
	res.top = at(cx, 0);
	res.bottom = at(cx, H - 1);
	res.corner = at(0, 0);
	return res;
}

}  // namespace bims::ego
