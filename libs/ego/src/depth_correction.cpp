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

/** The frame pairs (every step-th frame) min_gap..max_gap apart. */
std::vector<std::pair<int, int>> framePairs(int n, const DepthFitOptions& o)
{
	std::vector<std::pair<int, int>> pairs;
	for (int i = 0; i < n; i += o.step)
		for (int j = 0; j < n; j += o.step)
			if (std::abs(i - j) >= o.min_gap && std::abs(i - j) <= o.max_gap)
				pairs.emplace_back(i, j);
	if (pairs.empty())
		throw std::invalid_argument(
		    "estimateDepthCorrection: no frame pair " +
		    std::to_string(o.min_gap) + ".." + std::to_string(o.max_gap) +
		    " frames apart (give a longer static stretch)");
	return pairs;
}

/** The normal equations of the coefficients' update, over sampled readings
 * of frame j against frame i's surface. */
struct DepthNormalEquations
{
	Mat A = Mat::Zero();
	Vec b = Vec::Zero();
	double sum2 = 0;
	size_t count = 0;

	/** \a samples random readings of \a dj (intrinsics \a Kj) moved by
	 * T_ij onto the reference level \a L. */
	void addPair(const DenseLevel& L, const Eigen::Matrix3d& Kj,
	             const cv::Mat& dj, const Eigen::Matrix4d& T,
	             const DepthFitOptions& o, std::mt19937& rng)
	{
		const Eigen::Matrix3d R = T.block<3, 3>(0, 0);
		const Eigen::Vector3d t = T.block<3, 1>(0, 3);
		std::uniform_int_distribution<int> pu(0, dj.cols - 1),
		    pv(0, dj.rows - 1);
		for (int s = 0; s < o.samples_per_pair; s++)
		{
			const int u = pu(rng), v = pv(rng);
			const double z = dj.at<float>(v, u);
			if (!(z >= o.min_depth_m && z <= o.max_depth_m)) continue;
			const double xj = (u - Kj(0, 2)) / Kj(0, 0),
			             yj = (v - Kj(1, 2)) / Kj(1, 1);
			const Eigen::Vector3d RX = R * Eigen::Vector3d(xj * z, yj * z, z);
			addReading(L, RX, RX + t, xj, yj, o);
		}
	}

	/** One reading: RX its rotated point, Y = RX + t in the reference. */
	void addReading(const DenseLevel& L, const Eigen::Vector3d& RX,
	                const Eigen::Vector3d& Y, double xj, double yj,
	                const DepthFitOptions& o)
	{
		if (Y.z() <= 0) return;
		const int ui = static_cast<int>(
		              std::lround(L.fx * Y.x() / Y.z() + L.cx)),
		          vi = static_cast<int>(
		              std::lround(L.fy * Y.y() / Y.z() + L.cy));
		if (ui < 0 || vi < 0 || ui >= L.depth.cols || vi >= L.depth.rows)
			return;
		const RefPixel& q =
		    L.packed[static_cast<size_t>(vi) * L.depth.cols + ui];
		if (q.z <= 0 || (q.nx == 0 && q.ny == 0 && q.nz == 0)) return;
		if (std::abs(Y.z() - q.z) > 0.1 * q.z) return;
		const Eigen::Vector3d nq(q.nx, q.ny, q.nz);
		const double r = nq.dot(Y) - q.d;
		const double xi = (ui - L.cx) / L.fx, yi = (vi - L.cy) / L.fy;
		const Eigen::Vector3d Xi(xi * q.z, yi * q.z, q.z);
		// d r / d a: the current point scales with its factor, the
		// reference point with its own
		const Vec J =
		    nq.dot(RX) * basisVec(xj, yj) - nq.dot(Xi) * basisVec(xi, yi);
		const double w = std::abs(r) <= o.huber_m ? 1 : o.huber_m / std::abs(r);
		A += w * J * J.transpose();
		b += w * J * r;
		sum2 += w * r * r;
		++count;
	}
};

/** The depth of every step-th frame corrected with the coefficients \a a,
 * and its reference (normals at half size, as the alignment). */
void correctedReferences(const std::vector<RgbdFrame>& frames, const Vec& a,
                         const DepthFitOptions& o, std::vector<cv::Mat>& depth,
                         std::vector<DenseFrame>& ref)
{
	AnchorParams ap;
	ap.finest_level = 1;
	ap.coarsest_level = 1;
	ap.min_depth_m = o.min_depth_m;
	ap.max_depth_m = o.max_depth_m;
	DepthCorrectionParams cur;
	cur.enable = true;
	for (int k = 0; k < kDepthCorrectionTerms; k++) cur.coefficients[k] = a[k];
	DepthCorrection corr(cur);
	ref.assign(frames.size(), DenseFrame());
	depth.assign(frames.size(), cv::Mat());
	for (size_t i = 0; i < frames.size(); i += size_t(o.step))
	{
		if (frames[i].depth.size() != frames[0].depth.size())
			throw std::invalid_argument(
			    "estimateDepthCorrection: frames of different sizes");
		depth[i] = frames[i].depth.clone();
		corr.apply(depth[i], frames[i].K);
		ref[i].build(frames[i].grey, depth[i], frames[i].K, ap);
		ref[i].prepareReference(ap);
	}
}

/** The correction (1 + delta) at the borders and a corner of the first
 * frame's image, for the report. */
void borderCorrections(const RgbdFrame& f, const Vec& a, DepthFitResult& res)
{
	const double fx = f.K(0, 0), fy = f.K(1, 1), cx = f.K(0, 2), cy = f.K(1, 2);
	const int W = f.depth.cols, H = f.depth.rows;
	auto at = [&](double u, double v)
	{ return basisVec((u - cx) / fx, (v - cy) / fy).dot(a); };
	res.left = at(0, cy);
	res.right = at(W - 1, cy);
	res.top = at(cx, 0);
	res.bottom = at(cx, H - 1);
	res.corner = at(0, 0);
}
}  // namespace

DepthFitResult estimateDepthCorrection(const std::vector<RgbdFrame>& frames,
                                       const std::vector<Eigen::Matrix4d>& T_WC,
                                       const DepthFitOptions& o)
{
	if (frames.size() != T_WC.size())
		throw std::invalid_argument(
		    "estimateDepthCorrection: frames and poses differ in number");
	const auto pairs = framePairs(static_cast<int>(frames.size()), o);
	DepthFitResult res;
	res.pairs = static_cast<int>(pairs.size());
	Vec a = Vec::Zero();
	std::vector<DenseFrame> ref;
	std::vector<cv::Mat> depth;
	for (int it = 0; it < o.iterations; it++)
	{
		correctedReferences(frames, a, o, depth, ref);
		DepthNormalEquations ne;
		std::mt19937 rng(1);
		for (const auto& [i, j] : pairs)
			ne.addPair(ref[i].levels[1], frames[j].K, depth[j],
			           T_WC[i].inverse() * T_WC[j], o, rng);
		if (ne.count < static_cast<size_t>(10 * kDepthCorrectionTerms))
			throw std::invalid_argument(
			    "estimateDepthCorrection: too few overlapping readings (" +
			    std::to_string(ne.count) + ")");
		const double rms = std::sqrt(ne.sum2 / ne.count);
		if (it == 0) res.rms_before_m = rms;
		res.rms_after_m = rms;
		res.residuals = ne.count;
		ne.A.diagonal().array() += 1e-6 * ne.A.diagonal().mean();
		a -= ne.A.ldlt().solve(ne.b);
		if (!a.allFinite())
			throw std::runtime_error("estimateDepthCorrection: diverged");
	}
	res.params.enable = true;
	for (int k = 0; k < kDepthCorrectionTerms; k++)
		res.params.coefficients[k] = a[k];
	borderCorrections(frames.front(), a, res);
	return res;
}

}  // namespace bims::ego
