#include <bims/common/so3.h>
#include <bims/ego/dense_align.h>
#include <bims/ego/normal_equations.h>

#include <opencv2/imgproc.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bims::ego
{
namespace
{
/** 2x2 block depth: the mean of the readings that agree, else none. */
inline float blockDepth(const float z[4])
{
	float lo = 1e30f, hi = 0, sum = 0;
	int n = 0;
	for (int i = 0; i < 4; i++)
		if (z[i] > 0)
		{
			lo = std::min(lo, z[i]);
			hi = std::max(hi, z[i]);
			sum += z[i];
			++n;
		}
	return (n > 0 && hi - lo <= 0.03f * lo + 0.01f) ? sum / n : 0.f;
}

cv::Mat downsampleDepth(const cv::Mat& d)
{
	const int W = d.cols / 2, H = d.rows / 2;
	cv::Mat out(H, W, CV_32FC1);
	for (int v = 0; v < H; v++)
	{
		const float* r0 = d.ptr<float>(2 * v);
		const float* r1 = d.ptr<float>(2 * v + 1);
		float* o = out.ptr<float>(v);
		for (int u = 0; u < W; u++)
		{
			const float z[4] = {r0[2 * u], r0[2 * u + 1], r1[2 * u],
			                    r1[2 * u + 1]};
			o[u] = blockDepth(z);
		}
	}
	return out;
}

/** \a b's intrinsics: those of \a a at half the size (pixel centres). */
void halveIntrinsics(const DenseLevel& a, DenseLevel& b)
{
	b.fx = a.fx / 2;
	b.fy = a.fy / 2;
	b.cx = (a.cx + 0.5f) / 2 - 0.5f;
	b.cy = (a.cy + 0.5f) / 2 - 0.5f;
}

/** Unit normals from the depth's central differences, facing the camera;
 * none at depth edges and where a neighbour has no reading. */
cv::Mat normalsOf(const DenseLevel& L)
{
	const int W = L.depth.cols, H = L.depth.rows;
	cv::Mat n(H, W, CV_32FC3, cv::Scalar::all(0));
	auto P = [&L](int u, int v, float z) {
		return Eigen::Vector3f((u - L.cx) / L.fx * z, (v - L.cy) / L.fy * z, z);
	};
	for (int v = 1; v + 1 < H; v++)
	{
		const float* dm = L.depth.ptr<float>(v - 1);
		const float* d0 = L.depth.ptr<float>(v);
		const float* dp = L.depth.ptr<float>(v + 1);
		auto* o = n.ptr<cv::Vec3f>(v);
		for (int u = 1; u + 1 < W; u++)
		{
			const float z = d0[u], zl = d0[u - 1], zr = d0[u + 1], zu = dm[u],
			            zd = dp[u];
			if (z <= 0 || zl <= 0 || zr <= 0 || zu <= 0 || zd <= 0) continue;
			const float lim = 0.05f * z + 0.01f;
			if (std::abs(zr - zl) > 2 * lim || std::abs(zd - zu) > 2 * lim)
				continue;
			const Eigen::Vector3f dx = P(u + 1, v, zr) - P(u - 1, v, zl);
			const Eigen::Vector3f dy = P(u, v + 1, zd) - P(u, v - 1, zu);
			Eigen::Vector3f nn = dx.cross(dy);
			const float len = nn.norm();
			if (!(len > 0)) continue;
			nn /= len;
			if (nn.dot(P(u, v, z)) > 0) nn = -nn;
			o[u] = cv::Vec3f(nn.x(), nn.y(), nn.z());
		}
	}
	return n;
}

void pack(DenseLevel& L)
{
	const int W = L.depth.cols, H = L.depth.rows;
	L.packed.resize(static_cast<size_t>(W) * H);
	for (int v = 0; v < H; v++)
	{
		const float* z = L.depth.ptr<float>(v);
		const cv::Vec3f* n = L.normal.ptr<cv::Vec3f>(v);
		const float* g = L.grey.ptr<float>(v);
		const float* gx = L.gx.ptr<float>(v);
		const float* gy = L.gy.ptr<float>(v);
		RefPixel* o = &L.packed[static_cast<size_t>(v) * W];
		for (int u = 0; u < W; u++)
		{
			const float px = (u - L.cx) / L.fx * z[u],
			            py = (v - L.cy) / L.fy * z[u];
			o[u] = {z[u],
			        n[u][0],
			        n[u][1],
			        n[u][2],
			        n[u][0] * px + n[u][1] * py + n[u][2] * z[u],
			        g[u],
			        gx[u],
			        gy[u]};
		}
	}
}

/** A sampled point of the current frame at one level. */
struct Sample
{
	float x, y, z, grey;
	int pix;        // v * W + u at the level
	bool excluded;  // predicted moving: not used in the fit
};

std::vector<Sample> samplesOf(const DenseLevel& L, int stride)
{
	std::vector<Sample> s;
	s.reserve(static_cast<size_t>(L.depth.total() / (stride * stride)));
	for (int v = 0; v < L.depth.rows; v += stride)
	{
		const float* d = L.depth.ptr<float>(v);
		const float* g = L.grey.ptr<float>(v);
		const uint8_t* e =
		    L.exclude.empty() ? nullptr : L.exclude.ptr<uint8_t>(v);
		for (int u = 0; u < L.depth.cols; u += stride)
		{
			const float z = d[u];
			if (z <= 0) continue;
			s.push_back({(u - L.cx) / L.fx * z, (v - L.cy) / L.fy * z, z, g[u],
			             v * L.depth.cols + u, e && e[u]});
		}
	}
	return s;
}

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

/** Normal equations of one pass, and its counts. */
struct Pass
{
	Mat6 H = Mat6::Zero();
	Vec6 b = Vec6::Zero();
	int associated = 0, inliers = 0;
	int occluding = 0;    ///< associated, in front of the reference surface
	int seenThrough = 0;  ///< associated, behind it
	double sumGeo2 = 0;
	/** Robust cost: Tukey loss of both terms; a sample off the reference
	 * or beyond the gate costs the loss's maximum (so that leaving the
	 * overlap is no gain). */
	double cost = 0;
	double photoSum = 0, photoW = 0;  // for the brightness offset
	// |photometric residual| histogram (2 grey levels a bin), for the scale
	static constexpr int kBins = 64;
	int photoHist[kBins] = {0};
	int photoN = 0;

	/** 1.4826 x the median |photometric residual| (robust scale). */
	double photoScaleEstimate() const
	{
		if (photoN == 0) return 0;
		int acc = 0;
		for (int i = 0; i < kBins; i++)
			if ((acc += photoHist[i]) * 2 >= photoN)
				return 1.4826 * (2 * i + 1);
		return 1.4826 * 2 * kBins;
	}
};

/** How a pass associates a sample with a reference pixel. */
struct Association
{
	/** The reference pixel of each sample (-1: none): written by a pass
	 * that projects (when \a record), read by one that keeps them. */
	std::vector<int> pixel;
	bool record = false;  ///< project, and write pixel
	bool keep = false;    ///< do not project: use pixel (the linear model)
	/** When \a residuals: each sample's point-to-plane residual in its
	 * noise's units (NaN where it has none: not associated, beyond the gate,
	 * no normal) and Tukey's weight s^2 of it. */
	bool residuals = false;
	std::vector<float> r, w;

	/** Before a pass over \a n samples: no pixel recorded, no residual. */
	void prepare(size_t n)
	{
		if (record) pixel.assign(n, -1);
		if (residuals)
		{
			r.assign(n, std::numeric_limits<float>::quiet_NaN());
			w.assign(n, 0.f);
		}
	}
};

/** A pass's pose in the loop's float arithmetic, and the reference's
 * camera. */
struct PassFrame
{
	float r00, r01, r02, r10, r11, r12, r20, r21, r22, t0, t1, t2;
	float fx, fy, cx, cy;
	int W, H;
	PassFrame(const DenseLevel& ref, const Eigen::Matrix3d& R,
	          const Eigen::Vector3d& t)
	    : r00(float(R(0, 0))),
	      r01(float(R(0, 1))),
	      r02(float(R(0, 2))),
	      r10(float(R(1, 0))),
	      r11(float(R(1, 1))),
	      r12(float(R(1, 2))),
	      r20(float(R(2, 0))),
	      r21(float(R(2, 1))),
	      r22(float(R(2, 2))),
	      t0(float(t[0])),
	      t1(float(t[1])),
	      t2(float(t[2])),
	      fx(ref.fx),
	      fy(ref.fy),
	      cx(ref.cx),
	      cy(ref.cy),
	      W(ref.depth.cols),
	      H(ref.depth.rows)
	{
	}
	/** The sample in the reference's camera. */
	void transform(const Sample& s, float& X, float& Y, float& Z) const
	{
		X = r00 * s.x + r01 * s.y + r02 * s.z + t0;
		Y = r10 * s.x + r11 * s.y + r12 * s.z + t1;
		Z = r20 * s.x + r21 * s.y + r22 * s.z + t2;
	}
	/** The reference pixel nearest to (u, v), -1 outside the image. */
	int nearestPixel(float u, float v) const
	{
		if (!(u > -0.5f && v > -0.5f && u < W - 0.5f && v < H - 0.5f))
			return -1;
		return static_cast<int>(v + 0.5f) * W + static_cast<int>(u + 0.5f);
	}
};

/** A pass's optional outputs (each may be null): 255 in \a outliers at the
 * samples associated but not inliers, the reference pixels the frame sees
 * through, 255 in \a consistent at the inliers, the association. */
struct PassOutputs
{
	cv::Mat* outliers;
	std::vector<int>* seenThrough;
	cv::Mat* consistent;
	Association* assoc;
};

/** A sample associated with reference reading \a zr beyond the depth gate
 * (seen through the reference's surface, or in front of it): its counts
 * and cost. false when it is on the surface. */
bool offSurface(float zr, float Z, const Sample& s, int pix, bool counts,
                const AnchorParams& p, const PassOutputs& o, Pass& out)
{
	const float gate = float(p.gate_m + p.gate_z2 * zr * zr);
	const double rhoMax = p.tukey_c * p.tukey_c / 6;
	if (zr > 0 && Z > zr + gate)
	{
		// The current frame sees through the reference's surface: that
		// surface was not static (it has moved away); the current point
		// is no outlier of its own frame.
		if (!counts) return true;
		++out.associated;
		++out.seenThrough;
		if (o.seenThrough) o.seenThrough->push_back(pix);
		out.cost += rhoMax;
		return true;
	}
	if (zr < 0 || Z < zr - gate)
	{
		// In front of the reference's surface: an occluder (moving, or
		// static but new), no evidence against the pose. Or where the
		// reference saw something moving (zr < 0): covered (no reason
		// for a new keyframe), and likely moving itself.
		if (o.outliers) o.outliers->data[s.pix] = 255;
		if (!counts) return true;
		++out.associated;
		++out.occluding;
		out.cost += rhoMax;
		return true;
	}
	return false;
}

/** The point-to-plane term of a sample associated on the reference's
 * surface q (X, Y, Z: the sample in the reference's camera): the
 * classification images, the counts, the cost and, with \a rows, the
 * normal equations' row. true when the sample goes on to the photometric
 * term (it counts and is an inlier). */
bool geometricTerm(const RefPixel& q, const Sample& s, size_t i, float X,
                   float Y, float Z, bool counts, const AnchorParams& p,
                   NormalEquations6* rows, const PassOutputs& o, Pass& out)
{
	// no normal at depth edges: no geometric term there (weight 1, no
	// cost), but the photometric one (where the texture is) still applies
	const bool hasNormal = !(q.nx == 0 && q.ny == 0 && q.nz == 0);
	const double c = p.tukey_c;
	Tukey tg{1, 0};
	double rg = 0, invSg = 1;
	if (hasNormal)
	{
		rg = pointToPlaneResidual(X, Y, Z, q.nx, q.ny, q.nz, q.d);
		invSg = 1 / (p.geo_sigma_m + p.geo_sigma_z2 * q.z * q.z);
		tg = Tukey::at(rg * invSg * (1 / c), c);
		if (o.assoc && o.assoc->residuals)
		{
			o.assoc->r[i] = float(rg * invSg);
			o.assoc->w[i] = float(tg.s * tg.s);
		}
	}
	if (tg.s <= 0 && o.outliers) o.outliers->data[s.pix] = 255;
	if (tg.s > 0 && o.consistent) o.consistent->data[s.pix] = 255;
	if (!counts) return false;
	++out.associated;
	out.cost += tg.loss;
	if (tg.s <= 0) return false;
	++out.inliers;
	out.sumGeo2 += rg * rg;
	if (hasNormal && rows)
	{
		// point-to-plane: d r / d(v, w) = [n, X x n]
		float Jg[6];
		pointToPlaneJacobian(X, Y, Z, q.nx, q.ny, q.nz, Jg);
		// weight s^2 / sg^2
		rows->add(Jg, tg.s * invSg, rg);
	}
	return true;
}

/** The photometric term of a pass: the reference's grey level, bilinear
 * at the sample's projection, against the sample's plus the offset. */
struct PhotometricTerm
{
	const PassFrame& f;
	const RefPixel* P;
	float offset;
	double weight;  ///< photo_weight
	double c;       ///< Tukey's constant
	/** the residual's a = r / (sp c), and the square root of its weight's
	 * scale, photo_weight / sp^2 */
	double a, rootScale;

	void add(const Sample& s, float X, float Y, float Z, float iz, float u,
	         float v, NormalEquations6* rows, Pass& out) const
	{
		const int W = f.W;
		if (!(u >= 0 && v >= 0 && u < W - 1 && v < f.H - 1))
		{
			out.cost += weight * (c * c / 6);
			return;
		}
		const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
		const float au = u - u0, av = v - v0;
		const RefPixel& a0 = P[v0 * W + u0];
		const RefPixel& a1 = P[v0 * W + u0 + 1];
		const RefPixel& b0 = P[(v0 + 1) * W + u0];
		const RefPixel& b1 = P[(v0 + 1) * W + u0 + 1];
		const float w00 = (1 - av) * (1 - au), w01 = (1 - av) * au,
		            w10 = av * (1 - au), w11 = av * au;
		auto bil = [&](float RefPixel::*m)
		{ return w00 * a0.*m + w01 * a1.*m + w10 * b0.*m + w11 * b1.*m; };
		const float Ir = bil(&RefPixel::g);
		const double rp = Ir - s.grey - offset;
		++out.photoN;
		++out.photoHist[std::min(Pass::kBins - 1,
		                         static_cast<int>(std::abs(rp) * 0.5))];
		const Tukey tp = Tukey::at(rp * a, c);
		const double wp = tp.s * tp.s;
		out.cost += weight * tp.loss;
		out.photoSum += wp * (Ir - s.grey);
		out.photoW += wp;
		if (wp <= 0 || !rows) return;
		const float gx = bil(&RefPixel::gx), gy = bil(&RefPixel::gy);
		float Jp[6];
		photometricJacobian(X, Y, Z, iz, gx, gy, f.fx, f.fy, Jp);
		rows->add(Jp, tp.s * rootScale, rp);
	}
};

/** One pass over the samples at pose (R, t): the normal equations (with
 * \a rows, their scratch) and the counts; \a outliers (optional) gets 255 at
 * the samples that are associated but not inliers. \a assoc (optional):
 * record each sample's reference pixel, or keep the recorded ones instead
 * of projecting. */
Pass pass(const DenseLevel& ref, const std::vector<Sample>& cur,
          const Eigen::Matrix3d& R, const Eigen::Vector3d& t, float offset,
          double photoSigma, const AnchorParams& p, NormalEquations6* rows,
          cv::Mat* outliers, std::vector<int>* seenThrough = nullptr,
          cv::Mat* consistent = nullptr, Association* assoc = nullptr)
{
	const PassOutputs o{outliers, seenThrough, consistent, assoc};
	const bool record = assoc && assoc->record,
	           keep = assoc && assoc->keep && !record;
	if (assoc) assoc->prepare(cur.size());
	Pass out;
	const PassFrame f(ref, R, t);
	const float zmin = float(p.min_depth_m);
	const double c = p.tukey_c, rhoMax = c * c / 6;
	const bool photo = p.photo_weight > 0 && !outliers;
	const double photoScale = p.photo_weight / (photoSigma * photoSigma);
	const RefPixel* P = ref.packed.data();
	const PhotometricTerm photometric{f,
	                                  P,
	                                  offset,
	                                  p.photo_weight,
	                                  c,
	                                  1 / (photoSigma * c),
	                                  std::sqrt(photoScale)};
	if (rows) rows->clear();
	for (size_t i = 0; i < cur.size(); i++)
	{
		const Sample& s = cur[i];
		// excluded samples (predicted moving) only get classified, in the
		// final pass, for the outlier image
		if (s.excluded && !outliers) continue;
		const bool counts = !s.excluded;
		float X, Y, Z;
		f.transform(s, X, Y, Z);
		float u = 0, v = 0, iz = 0;
		int pix = -1;
		if (Z >= zmin)
		{
			iz = 1.f / Z;
			denseProject(X, Y, iz, f.fx, f.fy, f.cx, f.cy, u, v);
			pix = keep ? assoc->pixel[i] : f.nearestPixel(u, v);
			if (record) assoc->pixel[i] = pix;
		}
		const float zr = pix < 0 ? 0.f : P[pix].z;
		if (zr == 0)  // in no reference reading (or too near)
		{
			if (counts) out.cost += rhoMax;
			continue;
		}
		if (offSurface(zr, Z, s, pix, counts, p, o, out)) continue;
		if (!geometricTerm(P[pix], s, i, X, Y, Z, counts, p, rows, o, out))
			continue;
		if (photo) photometric.add(s, X, Y, Z, iz, u, v, rows, out);
	}
	if (rows) rows->get(out.H, out.b);
	return out;
}

}  // namespace

namespace
{
/** A depth reading inside [zmin, zmax], else 0 (no reading; NaN fails both
 * comparisons). */
struct Readings
{
	float zmin, zmax;
	float operator()(float z) const
	{
		return (z >= zmin && z <= zmax) ? z : 0.f;
	}
};

/** Level 0: the input's readings and grey levels. */
void fullLevel(const cv::Mat& depth, const cv::Mat& grey, Readings reading,
               DenseLevel& L0)
{
	L0.depth.create(depth.size(), CV_32FC1);
	for (int v = 0; v < depth.rows; v++)
	{
		const float* d = depth.ptr<float>(v);
		float* o = L0.depth.ptr<float>(v);
		for (int u = 0; u < depth.cols; u++) o[u] = reading(d[u]);
	}
	grey.convertTo(L0.grey, CV_32F);
}

/** Level 1 straight from the input (level 0 is not used): the same
 * readings and the same 2x2 rules, in one pass. */
void halfLevel(const cv::Mat& depth, const cv::Mat& grey, Readings reading,
               const DenseLevel& L0, DenseLevel& L1)
{
	const int W = depth.cols / 2, H = depth.rows / 2;
	L1.depth.create(H, W, CV_32FC1);
	L1.grey.create(H, W, CV_32FC1);
	for (int v = 0; v < H; v++)
	{
		const float* d0 = depth.ptr<float>(2 * v);
		const float* d1 = depth.ptr<float>(2 * v + 1);
		const uint8_t* g0 = grey.ptr<uint8_t>(2 * v);
		const uint8_t* g1 = grey.ptr<uint8_t>(2 * v + 1);
		float* od = L1.depth.ptr<float>(v);
		float* og = L1.grey.ptr<float>(v);
		for (int u = 0; u < W; u++)
		{
			const int a = 2 * u, b = 2 * u + 1;
			og[u] = 0.25f * float(g0[a] + g0[b] + g1[a] + g1[b]);
			const float z[4] = {reading(d0[a]), reading(d0[b]), reading(d1[a]),
			                    reading(d1[b])};
			od[u] = blockDepth(z);
		}
	}
	halveIntrinsics(L0, L1);
}

/** The excluded pixels of every level: a pixel is excluded when any of the
 * pixels it covers is (INTER_AREA: any non-zero stays non-zero). */
void excludedPixels(const cv::Mat& exclude, std::vector<DenseLevel>& levels)
{
	const cv::Mat* src = &exclude;
	for (size_t l = 0; l < levels.size(); l++)
	{
		DenseLevel& L = levels[l];
		if (l == 0 && L.depth.empty()) continue;
		if (src->size() == L.depth.size())
			L.exclude = src->clone();
		else
			cv::resize(*src, L.exclude, L.depth.size(), 0, 0, cv::INTER_AREA);
		src = &L.exclude;
	}
}
}  // namespace

void DenseFrame::build(const cv::Mat& image, const cv::Mat& depth,
                       const Eigen::Matrix3d& K, const AnchorParams& p,
                       const cv::Mat& exclude)
{
	CV_Assert(depth.type() == CV_32FC1);
	CV_Assert(image.empty() ||
	          (image.type() == CV_8UC1 && image.size() == depth.size()));
	CV_Assert(exclude.empty() ||
	          (exclude.type() == CV_8UC1 && exclude.size() == depth.size()));
	reference_ = false;
	image_ = !image.empty();
	// depth only: the levels' grey stays flat (no gradient, no photometric
	// term: alignDense() drops it)
	if (!image_ && noImage_.size() != depth.size())
		noImage_ = cv::Mat::zeros(depth.size(), CV_8UC1);
	const cv::Mat& grey = image_ ? image : noImage_;
	levels.assign(static_cast<size_t>(p.coarsest_level) + 1, DenseLevel());
	const Readings reading{float(p.min_depth_m), float(p.max_depth_m)};
	DenseLevel& L0 = levels[0];
	L0.fx = float(K(0, 0));
	L0.fy = float(K(1, 1));
	L0.cx = float(K(0, 2));
	L0.cy = float(K(1, 2));
	size_t first = 1;
	if (p.finest_level == 0 || levels.size() == 1)
		fullLevel(depth, grey, reading, L0);
	else
	{
		halfLevel(depth, grey, reading, L0, levels[1]);
		first = 2;
	}
	for (size_t l = first; l < levels.size(); l++)
	{
		const DenseLevel& a = levels[l - 1];
		DenseLevel& b = levels[l];
		b.depth = downsampleDepth(a.depth);
		cv::resize(a.grey, b.grey, b.depth.size(), 0, 0, cv::INTER_AREA);
		halveIntrinsics(a, b);
	}
	if (!exclude.empty()) excludedPixels(exclude, levels);
}

void DenseFrame::prepareReference(const AnchorParams& p)
{
	for (int l = p.finest_level; l < static_cast<int>(levels.size()); l++)
	{
		DenseLevel& L = levels[static_cast<size_t>(l)];
		cv::Sobel(L.grey, L.gx, CV_32F, 1, 0, 3, 1.0 / 8);
		cv::Sobel(L.grey, L.gy, CV_32F, 0, 1, 3, 1.0 / 8);
		L.normal = normalsOf(L);
		pack(L);
	}
	reference_ = true;
}

namespace
{
/** The priors of one level's Gauss-Newton: the rotation's (the IMU's;
 * fixed without a sigma) and the translation's (the inertial filter's):
 * their cost, their rows and the damped step. */
struct LevelPriors
{
	const Eigen::Matrix3d* R_prior;
	const TranslationPrior* tPrior;
	bool fixRotation;
	double wPrior;

	LevelPriors(const Eigen::Matrix3d* R, double sigma_rad,
	            const TranslationPrior* t)
	    : R_prior(R),
	      tPrior(t),
	      fixRotation(R && !(sigma_rad > 0)),
	      wPrior(R && !fixRotation ? 1 / (sigma_rad * sigma_rad) : 0)
	{
	}
	double cost(const Eigen::Matrix3d& Rx, const Eigen::Vector3d& tx) const
	{
		double c =
		    wPrior > 0
		        ? 0.5 * wPrior * logSO3(R_prior->transpose() * Rx).squaredNorm()
		        : 0.0;
		if (tPrior)
		{
			const Eigen::Vector3d e = tx - tPrior->t;
			c += 0.5 * e.dot(tPrior->info * e);
		}
		return c;
	}
	/** Adds the priors' rows at (R, t) to the normal equations. */
	void addTo(Mat6& H, Vec6& b, const Eigen::Matrix3d& R,
	           const Eigen::Vector3d& t) const
	{
		if (wPrior > 0)
		{
			// r = Log(R_prior^T R), dr/dw ~ R^T (left perturbation)
			const Eigen::Vector3d e = logSO3(R_prior->transpose() * R);
			H.block<3, 3>(3, 3) += wPrior * Eigen::Matrix3d::Identity();
			b.segment<3>(3) += wPrior * (R * e);
		}
		if (tPrior)
		{
			// r = t - t_prior; t <- Exp(w) t + v: dr/d(v, w) = [I, -[t]x]
			Eigen::Matrix<double, 3, 6> J;
			J.leftCols<3>().setIdentity();
			J.rightCols<3>() = -skew(t);
			if (fixRotation) J.rightCols<3>().setZero();
			H += J.transpose() * tPrior->info * J;
			b += J.transpose() * (tPrior->info * (t - tPrior->t));
		}
	}
	/** The Levenberg-Marquardt step (v, w) of H d = -b, damped by \a lambda
	 * (the translation only when the rotation is fixed). */
	Vec6 step(Mat6 H, const Vec6& b, double lambda) const
	{
		Vec6 d = Vec6::Zero();
		if (fixRotation)
		{
			Eigen::Matrix3d A = H.topLeftCorner<3, 3>();
			A.diagonal() *= 1 + lambda;
			d.head<3>() = A.ldlt().solve(-b.head<3>());
		}
		else
		{
			H.diagonal() *= 1 + lambda;
			d = H.ldlt().solve(-b);
		}
		return d;
	}
};

/** Levenberg-Marquardt at one level from (R, t): a step is taken only if
 * it lowers the robust cost (the photometric scale and brightness offset
 * stay fixed within the level, so that costs compare; they are estimated
 * afresh for the next level at the end). \a first: the pass at (R, t)
 * with this offset and scale, when already made (unused when the rotation
 * is held at the prior). Returns the steps taken. */
int iterateLevel(const DenseLevel& Lr, const std::vector<Sample>& samples,
                 Eigen::Matrix3d& R, Eigen::Vector3d& t, float& offset,
                 double& photoSigma, const AnchorParams& p,
                 const Eigen::Matrix3d* R_prior, double sigmaPrior_rad,
                 const TranslationPrior* tPrior, NormalEquations6& rows,
                 int* inliers, const Pass* first = nullptr,
                 Mat6* information = nullptr)
{
	const LevelPriors priors(R_prior, sigmaPrior_rad, tPrior);
	if (priors.fixRotation) R = *R_prior;
	Pass cur =
	    first && !priors.fixRotation
	        ? *first
	        : pass(Lr, samples, R, t, offset, photoSigma, p, &rows, nullptr);
	double curCost = cur.cost + priors.cost(R, t);
	double lambda = 1e-4;
	int steps = 0;
	for (int it = 0; it < p.iterations && cur.inliers >= 6; it++)
	{
		Mat6 H = cur.H;
		Vec6 b = cur.b;
		priors.addTo(H, b, R, t);
		const Vec6 d = priors.step(H, b, lambda);
		if (!d.allFinite()) break;
		const Eigen::Matrix3d dR = expSO3(d.segment<3>(3));
		const Eigen::Matrix3d Rn = dR * R;
		const Eigen::Vector3d tn = dR * t + d.head<3>();
		Pass nxt =
		    pass(Lr, samples, Rn, tn, offset, photoSigma, p, &rows, nullptr);
		const double nxtCost = nxt.cost + priors.cost(Rn, tn);
		++steps;
		if (nxtCost < curCost)
		{
			R = Rn;
			t = tn;
			cur = std::move(nxt);
			curCost = nxtCost;
			lambda = std::max(lambda / 3, 1e-7);
			if (d.head<3>().norm() < 1e-5 && d.tail<3>().norm() < 1e-5) break;
		}
		else
		{
			lambda *= 8;
			if (lambda > 1e3) break;
		}
	}
	if (inliers) *inliers = cur.inliers;
	if (information) *information = cur.H;
	// the next level's photometric scale and brightness offset, from the
	// residuals at this level's result
	photoSigma = std::max(p.photo_sigma_grey, cur.photoScaleEstimate());
	if (cur.photoW > 0) offset = float(cur.photoSum / cur.photoW);
	return steps;
}

/** \a H with the depth's information about the translation measured on
 * the geometry itself. H is the data's curvature with every point held on
 * the reference pixel it lands on now (the Jacobian of the point-to-plane
 * residual). Along a flat wall that is the wall's noisy normals: they give
 * its in-plane directions information that sliding along the wall does not
 * bear out (the slid points land on other pixels of the same plane, where
 * the residual is noise again). So along each eigenvector d of the
 * geometric term's translation block (eigenvalue a) the frame is slid by
 * +- delta (max(2 / sqrt(a), 2 pixels' footprint at the samples' median
 * depth)) and each point's residual evaluated twice: re-associated (what
 * the geometry says) and on the pixel it had (what H says). The regression
 * gain of the first change on the second (Tukey-weighted, over the inliers
 * at the result that stay within the gate) is how much of H's sensitivity
 * is real: the geometric information along d is scaled by its square,
 * clamped to [0, 1] (a congruence: H stays positive semi-definite). A
 * planar world with exact normals gives a gain of 1 (a point re-associated
 * on the same plane has the same residual); a flat wall's in-plane
 * directions ~0. The photometric information is kept as it is.
 * docs/ego.md, "Depth-inertial translation". */
Mat6 measuredInformation(const DenseLevel& ref, const std::vector<Sample>& cur,
                         const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                         const AnchorParams& params, const Mat6& H,
                         NormalEquations6& rows)
{
	AnchorParams p = params;
	p.photo_weight = 0;
	Association at;
	at.record = true;
	at.residuals = true;
	const Pass atPass =
	    pass(ref, cur, R, t, 0, 1, p, &rows, nullptr, nullptr, nullptr, &at);
	const Mat6 Hgeo = atPass.H;
	const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(
	    Hgeo.topLeftCorner<3, 3>());
	if (es.info() != Eigen::Success) return H;
	// one pixel's footprint at the samples' median depth [m]
	std::vector<float> z;
	z.reserve(cur.size());
	for (const Sample& s : cur)
		if (!s.excluded) z.push_back(s.z);
	if (z.empty()) return H;
	std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
	const double pixel = z[z.size() / 2] / std::max(ref.fx, ref.fy);
	Association moved, held;
	moved.residuals = held.residuals = true;
	held.keep = true;
	held.pixel = std::move(at.pixel);  // not read again
	Eigen::Vector3d scale = Eigen::Vector3d::Ones();
	for (int k = 0; k < 3; k++)
	{
		const double a = es.eigenvalues()[k];
		if (!(a > 0)) continue;
		const Eigen::Vector3d d = es.eigenvectors().col(k);
		const double delta = std::max(2 / std::sqrt(a), 2 * pixel);
		double sxy = 0, sxx = 0;
		for (const double sign : {1.0, -1.0})
		{
			const Eigen::Vector3d tn = t + sign * delta * d;
			pass(ref, cur, R, tn, 0, 1, p, nullptr, nullptr, nullptr, nullptr,
			     &moved);
			pass(ref, cur, R, tn, 0, 1, p, nullptr, nullptr, nullptr, nullptr,
			     &held);
			for (size_t i = 0; i < cur.size(); i++)
			{
				const double w = at.w[i];
				if (!(w > 0) || std::isnan(moved.r[i]) || std::isnan(held.r[i]))
					continue;
				const double x = held.r[i] - at.r[i], y = moved.r[i] - at.r[i];
				sxy += w * x * y;
				sxx += w * x * x;
			}
		}
		const double gain = sxx > 0 ? std::clamp(sxy / sxx, 0.0, 1.0) : 1.0;
		scale[k] = gain;
	}
	Mat6 S = Mat6::Identity();
	S.topLeftCorner<3, 3>() =
	    es.eigenvectors() * scale.asDiagonal() * es.eigenvectors().transpose();
	return H - Hgeo + S * Hgeo * S;
}
}  // namespace

void DenseFrame::dropReadings(const cv::Mat& m, const AnchorParams& p)
{
	const size_t f = static_cast<size_t>(p.finest_level);
	if (levels.size() <= f || levels[f].depth.empty()) return;
	const int W = levels[f].depth.cols, H = levels[f].depth.rows;
	CV_Assert(m.type() == CV_8UC1 && m.cols == W && m.rows == H);
	for (size_t l = f; l < levels.size(); l++)
	{
		DenseLevel& L = levels[l];
		const int k = static_cast<int>(l - f);
		for (int v = 0; v < H; v++)
		{
			const uint8_t* row = m.ptr<uint8_t>(v);
			for (int u = 0; u < W; u++)
			{
				if (!row[u]) continue;
				const int uu = u >> k, vv = v >> k;
				if (uu >= L.depth.cols || vv >= L.depth.rows) continue;
				L.depth.ptr<float>(vv)[uu] = 0;
				if (!L.normal.empty())
					L.normal.ptr<cv::Vec3f>(vv)[uu] = cv::Vec3f(0, 0, 0);
				if (!L.packed.empty())
				{
					// -1: known to be moving (not merely without a reading)
					RefPixel& q =
					    L.packed[static_cast<size_t>(vv) * L.depth.cols + uu];
					q.z = -1;
					q.nx = q.ny = q.nz = 0;
				}
			}
		}
	}
}

DenseAlignResult alignDense(const DenseFrame& ref, const DenseFrame& cur,
                            const Eigen::Matrix3d& R_init,
                            const Eigen::Vector3d& t_init,
                            const AnchorParams& p,
                            const Eigen::Matrix3d* R_prior,
                            double sigmaPrior_rad,
                            const TranslationPrior* tPrior)
{
	return alignDense(ref, cur, {{R_init, t_init}}, p, R_prior, sigmaPrior_rad,
	                  tPrior);
}

namespace
{
/** Where the alignment stands: the pose, the photometric term's brightness
 * offset and scale, and the data's normal equations there. */
struct Estimate
{
	Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
	Eigen::Vector3d t = Eigen::Vector3d::Zero();
	float offset = 0;
	double photoSigma = 0;
	Mat6 H = Mat6::Zero();
	int guess = 0;       ///< the initial guess it started from
	int iterations = 0;  ///< Gauss-Newton steps so far
};

/** The priors of one alignment (the arguments of alignDense()). */
struct Priors
{
	const Eigen::Matrix3d* R = nullptr;
	double sigmaR_rad = 0;
	const TranslationPrior* t = nullptr;
};

/** The coarsest level from each guess: the one with most inliers there.
 * A later guess is iterated only when it starts with more inliers than the
 * first one did (the frame-to-frame guess is usually the better one: 4
 * Gauss-Newton passes saved; docs/ego.md). */
Estimate bestCoarseGuess(const DenseLevel& Lr,
                         const std::vector<Sample>& coarse,
                         const std::vector<InitialGuess>& inits,
                         const AnchorParams& p, const Priors& pr,
                         NormalEquations6& rows)
{
	// a wide first scale; each pass then estimates it from its residuals
	const double sigma0 = std::max(p.photo_sigma_grey, 40.0);
	Estimate best;
	best.R = inits.front().R;
	best.t = inits.front().t;
	best.photoSigma = sigma0;
	int bestInliers = -1, iterations = 0;
	int firstInliers = -1;  // the first guess's, before iterating
	for (size_t k = 0; k < inits.size(); k++)
	{
		Estimate e;
		e.R = inits[k].R;
		e.t = inits[k].t;
		e.photoSigma = sigma0;
		e.guess = static_cast<int>(k);
		int inl = 0;
		// The first guess's count is also its level's first pass (with the
		// normal equations); a later one's only counts (it is usually not
		// iterated). A single guess needs no count.
		const bool reuse = inits.size() > 1 && k == 0;
		Pass counted;
		if (inits.size() > 1)
		{
			counted = pass(Lr, coarse, e.R, e.t, 0, sigma0, p,
			               reuse ? &rows : nullptr, nullptr);
			if (k == 0)
				firstInliers = counted.inliers;
			else if (counted.inliers <= firstInliers)
				continue;
		}
		iterations += iterateLevel(Lr, coarse, e.R, e.t, e.offset, e.photoSigma,
		                           p, pr.R, pr.sigmaR_rad, pr.t, rows, &inl,
		                           reuse ? &counted : nullptr, &e.H);
		if (inl > bestInliers)
		{
			bestInliers = inl;
			best = e;
		}
	}
	best.iterations = iterations;
	return best;
}

/** The finest level's counts, outlier and consistency images at \a e into
 * \a r, and whether the result holds (r.ok, r.why). */
void finalCounts(const DenseLevel& Lr, const DenseLevel& Lc,
                 const std::vector<Sample>& samples, const Estimate& e,
                 const AnchorParams& p, DenseAlignResult& r)
{
	r.outliers = cv::Mat::zeros(Lc.depth.size(), CV_8UC1);
	r.consistent = cv::Mat::zeros(Lc.depth.size(), CV_8UC1);
	const Pass fin = pass(Lr, samples, e.R, e.t, e.offset, e.photoSigma, p,
	                      nullptr, &r.outliers, &r.seenThrough, &r.consistent);
	if (p.stride_px > 1)
	{
		// a sample stands for its stride x stride block
		const cv::Mat k(p.stride_px, p.stride_px, CV_8UC1, cv::Scalar(1));
		cv::dilate(r.outliers, r.outliers, k, cv::Point(0, 0));
		cv::dilate(r.consistent, r.consistent, k, cv::Point(0, 0));
	}
	r.points = 0;
	for (const Sample& q : samples) r.points += q.excluded ? 0 : 1;
	r.associated = fin.associated;
	r.inliers = fin.inliers;
	// occluders and surfaces seen through are explained by motion in the
	// scene: the fraction is over the points that landed on a surface
	const int onSurface = fin.associated - fin.occluding - fin.seenThrough;
	r.inlier_fraction = onSurface > 0 ? double(fin.inliers) / onSurface : 0;
	r.overlap = r.points > 0 ? double(fin.inliers) / r.points : 0;
	r.coverage = r.points > 0 ? double(fin.associated) / r.points : 0;
	r.rms_geo_m = fin.inliers > 0 ? std::sqrt(fin.sumGeo2 / fin.inliers) : 0;
	if (!e.R.allFinite() || !e.t.allFinite())
		r.why = "diverged";
	else if (r.inliers < p.min_inliers)
		r.why = "too few inliers (" + std::to_string(r.inliers) + ")";
	else if (r.inlier_fraction < p.min_inlier_fraction)
		r.why = "inlier fraction " + std::to_string(r.inlier_fraction);
	r.ok = r.why.empty();
}
}  // namespace

DenseAlignResult alignDense(const DenseFrame& ref, const DenseFrame& cur,
                            const std::vector<InitialGuess>& inits,
                            const AnchorParams& params,
                            const Eigen::Matrix3d* R_prior,
                            double sigmaPrior_rad,
                            const TranslationPrior* tPrior)
{
	// the photometric term needs an image in both frames (else depth only)
	AnchorParams p = params;
	if (!ref.hasImage() || !cur.hasImage()) p.photo_weight = 0;
	DenseAlignResult r;
	if (!inits.empty())
	{
		r.R_RC = inits.front().R;
		r.t_RC = inits.front().t;
	}
	const int top = p.coarsest_level, fine = p.finest_level;
	if (!ref.isReference() || static_cast<int>(ref.levels.size()) <= top ||
	    static_cast<int>(cur.levels.size()) <= top || inits.empty())
	{
		r.why = inits.empty() ? "no initial guess"
		                      : "frames not prepared for these levels";
		return r;
	}
	const auto level = [](const DenseFrame& f, int l) -> const DenseLevel&
	{ return f.levels[static_cast<size_t>(l)]; };
	// about as many samples at every level: stride_px at the finest, half
	// that a level up, ...
	const auto samplesAt = [&](int l) {
		return samplesOf(level(cur, l), std::max(1, p.stride_px >> (l - fine)));
	};
	const Priors priors{R_prior, sigmaPrior_rad, tPrior};
	NormalEquations6 rows;
	std::vector<Sample> samples = samplesAt(top);
	Estimate e =
	    bestCoarseGuess(level(ref, top), samples, inits, p, priors, rows);
	for (int l = top - 1; l >= fine; l--)
	{
		samples = samplesAt(l);
		e.iterations +=
		    iterateLevel(level(ref, l), samples, e.R, e.t, e.offset,
		                 e.photoSigma, p, R_prior, sigmaPrior_rad, tPrior, rows,
		                 nullptr, nullptr, l == fine ? &e.H : nullptr);
	}
	// with a translation prior (the inertial filter's), the information is
	// its measurement's: measured on the cost where a pixel is exceeded
	if (tPrior)
		e.H = measuredInformation(level(ref, fine), samples, e.R, e.t, p, e.H,
		                          rows);
	finalCounts(level(ref, fine), level(cur, fine), samples, e, p, r);
	r.R_RC = orthonormalize(e.R);
	r.t_RC = e.t;
	r.information = e.H;
	r.guess = e.guess;
	r.iterations = e.iterations;
	return r;
}

Eigen::Matrix3d translationInformation(const Eigen::Matrix<double, 6, 6>& H,
                                       double rotationPriorInfo)
{
	const Eigen::Matrix3d Htt = H.topLeftCorner<3, 3>();
	if (std::isinf(rotationPriorInfo)) return Htt;
	Eigen::Matrix3d Hrr = H.bottomRightCorner<3, 3>();
	Hrr.diagonal().array() += rotationPriorInfo;
	const Eigen::Matrix3d Htr = H.topRightCorner<3, 3>();
	const Eigen::LDLT<Eigen::Matrix3d> ldlt(Hrr);
	if (ldlt.info() != Eigen::Success || Hrr.diagonal().minCoeff() <= 0)
		return Eigen::Matrix3d::Zero();
	const Eigen::Matrix3d S = Htt - Htr * ldlt.solve(Htr.transpose());
	return 0.5 * (S + S.transpose());
}

}  // namespace bims::ego
