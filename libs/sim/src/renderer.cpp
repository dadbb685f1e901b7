#include <bims/common/config.h>
#include <bims/sim/renderer.h>
#include <bims/sim/rng.h>
#include "ini_vector.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace bims::sim
{
using detail::kDeg;
namespace
{

/** Procedural texture: a grid of cells of random colours (strong corners for
 * KLT at every cell junction), plus a small per-cell darker dot pattern. */
inline void textureColor(uint32_t seed, int face, double s, double t,
                         double cell, double rgb[3])
{
	const double fs = s / cell, ft = t / cell;
	const int64_t ix = int64_t(std::floor(fs)), iy = int64_t(std::floor(ft));
	const uint64_t h = hash64(seed, uint64_t(face), uint64_t(ix), uint64_t(iy));
	for (int c = 0; c < 3; c++)
		rgb[c] = 35.0 + double((h >> (8 * c)) & 0xFF) * (200.0 / 255.0);
	// A dark square in one quadrant of some cells: more corners, no symmetry.
	if ((h >> 32) & 1)
	{
		const double u = fs - double(ix), v = ft - double(iy);
		const int q = int((h >> 33) & 3);
		const bool in = (q & 1 ? u > 0.55 : u < 0.45) &&
		                (q & 2 ? v > 0.55 : v < 0.45) &&
		                std::abs(u - 0.5) < 0.4 && std::abs(v - 0.5) < 0.4;
		if (in)
			for (int c = 0; c < 3; c++) rgb[c] *= 0.35;
	}
}
}  // namespace

void CameraParams::setResolution(const std::string& r)
{
	if (r == "640x480")
		width = 640, height = 480;
	else if (r == "320x240")
		width = 320, height = 240;
	else
		throw std::invalid_argument(
		    "resolution must be 640x480 or 320x240, got '" + r + "'");
}

void CameraParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section)
{
	ConfigSection s(cfg, section);
	setResolution(s.getChoice("resolution", "640x480", {"640x480", "320x240"}));
	fx = s.getDouble("fx", fx, 50, 5000);
	fy = s.getDouble("fy", fy, 50, 5000);
	cx = s.getDouble("cx", cx, 0, 639);
	cy = s.getDouble("cy", cy, 0, 479);
	s.finish();
}

void DepthParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                     const std::string& section)
{
	ConfigSection s(cfg, section);
	maxRange = s.getDouble("max_range", maxRange, 0.1, 60);
	minRange = s.getDouble("min_range", minRange, 0.0, 10);
	if (minRange >= maxRange)
		s.fail("min_range", "must be smaller than max_range");
	noiseA = s.getDouble("noise_a", noiseA, 0, 0.1);
	grazingDeg = s.getDouble("grazing_deg", grazingDeg, 1, 90);
	dropout = s.getDouble("dropout", dropout, 0, 1);
	holesPerMpx = s.getDouble("holes_per_mpx", holesPerMpx, 0, 10000);
	holeRadiusPx = s.getDouble("hole_radius_px", holeRadiusPx, 0.5, 100);
	projectorBaseline =
	    s.getDouble("projector_baseline", projectorBaseline, 0, 1);
	if (s.getBool("noiseless", false)) makeNoiseless();
	s.finish();
}

void RgbParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                   const std::string& section)
{
	ConfigSection s(cfg, section);
	enabled = s.getBool("enabled", enabled);
	noiseSigma = s.getDouble("noise_sigma", noiseSigma, 0, 100);
	ambient = s.getDouble("ambient", ambient, 0, 1);
	const auto l = s.getDoubles(
	    "light_dir", {lightDir_W.x(), lightDir_W.y(), lightDir_W.z()}, 3, -1e3,
	    1e3);
	lightDir_W = Eigen::Vector3d(l[0], l[1], l[2]);
	if (lightDir_W.norm() < 1e-9)
		s.fail("light_dir", "must not be the zero vector");
	s.finish();
}

Renderer::Renderer(const CameraParams& cam, const DepthParams& depth,
                   const RgbParams& rgb)
    : cam_(cam), depth_(depth), rgb_(rgb)
{
	xn_.resize(cam_.width);
	yn_.resize(cam_.height);
	for (int u = 0; u < cam_.width; u++) xn_[u] = (u - cam_.cxS()) / cam_.fxS();
	for (int v = 0; v < cam_.height; v++)
		yn_[v] = (v - cam_.cyS()) / cam_.fyS();
	rgb_.lightDir_W.normalize();
}

struct Renderer::Hits
{
	std::vector<Eigen::Matrix3d> R_PC;  ///< per primitive
	std::vector<Eigen::Vector3d> o_P;   ///< per primitive: camera in {P}
	std::vector<double> zbuf;           ///< per pixel: depth, +inf if none
	std::vector<int16_t> ibuf;          ///< per pixel: primitive, -1 if none
};

bool Renderer::screenRect(const Primitive& pr, const Eigen::Matrix3d& R_PC,
                          const Eigen::Vector3d& o_P, int rect[4]) const
{
	const int W = cam_.width, H = cam_.height;
	const double fx = cam_.fxS(), fy = cam_.fyS(), cx = cam_.cxS(),
	             cy = cam_.cyS();
	rect[0] = 0, rect[1] = W - 1, rect[2] = 0, rect[3] = H - 1;
	if (pr.shape == Shape::Room) return true;
	const Eigen::Vector3d h = pr.shape == Shape::Sphere
	                              ? Eigen::Vector3d::Constant(pr.half.x())
	                              : pr.half;
	double umin = 1e18, umax = -1e18, vmin = 1e18, vmax = -1e18;
	for (int c = 0; c < 8; c++)
	{
		const Eigen::Vector3d x_P(c & 1 ? h.x() : -h.x(),
		                          c & 2 ? h.y() : -h.y(),
		                          c & 4 ? h.z() : -h.z());
		const Eigen::Vector3d x_C = R_PC.transpose() * (x_P - o_P);
		if (x_C.z() < 1e-3) return true;  // partly behind: the whole image
		const double u = fx * x_C.x() / x_C.z() + cx,
		             v = fy * x_C.y() / x_C.z() + cy;
		umin = std::min(umin, u), umax = std::max(umax, u);
		vmin = std::min(vmin, v), vmax = std::max(vmax, v);
	}
	if (umax < -1 || vmax < -1 || umin > W || vmin > H) return false;
	rect[0] = std::max(0, int(std::floor(umin)) - 1);
	rect[1] = std::min(W - 1, int(std::ceil(umax)) + 1);
	rect[2] = std::max(0, int(std::floor(vmin)) - 1);
	rect[3] = std::min(H - 1, int(std::ceil(vmax)) + 1);
	return true;
}

void Renderer::nearestHits(const std::vector<Primitive>& prims,
                           const Eigen::Matrix3d& R_WC,
                           const Eigen::Vector3d& p_WC, Hits& h) const
{
	const int W = cam_.width;
	for (size_t i = 0; i < prims.size(); i++)
	{
		const Primitive& pr = prims[i];
		h.R_PC[i] = pr.R_WP.transpose() * R_WC;
		h.o_P[i] = pr.R_WP.transpose() * (p_WC - pr.t_WP);
		int rect[4];
		if (!screenRect(pr, h.R_PC[i], h.o_P[i], rect)) continue;
		const Eigen::Matrix3d& R = h.R_PC[i];
		const Eigen::Vector3d& o = h.o_P[i];
		for (int v = rect[2]; v <= rect[3]; v++)
		{
			const double y = yn_[v];
			for (int u = rect[0]; u <= rect[1]; u++)
			{
				const Eigen::Vector3d d =
				    R.col(0) * xn_[u] + R.col(1) * y + R.col(2);
				const double lam = intersectLocal(pr, o, d);
				const int k = v * W + u;
				if (lam < h.zbuf[k])
				{
					h.zbuf[k] = lam;
					h.ibuf[k] = int16_t(i);
				}
			}
		}
	}
}

void Renderer::shadeAndSense(const std::vector<Primitive>& prims, const Hits& h,
                             const Eigen::Matrix3d& R_WC, Rng& rng,
                             RenderedFrame& out) const
{
	const int W = cam_.width, H = cam_.height;
	const double cosGraze = std::cos(depth_.grazingDeg * kDeg);
	for (int v = 0; v < H; v++)
	{
		for (int u = 0; u < W; u++)
		{
			const int k = v * W + u;
			const int i = h.ibuf[k];
			if (i < 0) continue;
			const Primitive& pr = prims[size_t(i)];
			const double z = h.zbuf[k];
			const Eigen::Vector3d d_C(xn_[u], yn_[v], 1.0);
			const Eigen::Vector3d d_P = h.R_PC[i] * d_C;
			const SurfaceHit hit = surfaceAt(pr, h.o_P[i] + z * d_P);
			double col[3];
			textureColor(pr.texture, hit.face, hit.s, hit.t, pr.cell, col);
			const double shade =
			    rgb_.ambient + (1 - rgb_.ambient) *
			                       std::max(0.0, hit.n_W.dot(rgb_.lightDir_W));
			for (int c = 0; c < 3; c++)
			{
				double val = col[c] * shade;
				if (rgb_.noiseSigma > 0)
					val += rgb_.noiseSigma * rng.gaussFast();
				out.rgb[3 * size_t(k) + c] =
				    uint8_t(std::clamp(std::lround(val), 0L, 255L));
			}
			out.depthTrue[k] = float(z);
			out.objectId[k] = uint8_t(std::min(pr.objectId, 255));
			out.mask[k] = pr.objectId > 0 ? 255 : 0;
			// Depth sensor
			if (z > depth_.maxRange || z < depth_.minRange) continue;
			const Eigen::Vector3d d_W = R_WC * d_C;
			const double cosInc = std::abs(hit.n_W.dot(d_W)) / d_W.norm();
			if (cosInc < cosGraze) continue;
			if (depth_.dropout > 0 && rng.uniform() < depth_.dropout) continue;
			double zn = z;
			if (depth_.noiseA > 0) zn += depth_.noiseA * z * z * rng.gauss();
			const long mm = std::lround(zn * 1000.0);
			out.depthMm[k] = uint16_t(std::clamp(mm, 0L, 65535L));
		}
	}
}

void Renderer::projectorShadows(const Hits& h, RenderedFrame& out) const
{
	// A pixel's projector column is x_p = u - fx b / z. A surface point is
	// lit only if no point to its right (nearer to the projector's line of
	// sight) maps to a smaller projector column.
	const int W = cam_.width, H = cam_.height;
	const double fb = cam_.fxS() * depth_.projectorBaseline;
	for (int v = 0; v < H; v++)
	{
		double minXp = std::numeric_limits<double>::infinity();
		for (int u = W - 1; u >= 0; u--)
		{
			const int k = v * W + u;
			if (h.ibuf[k] < 0) continue;
			const double xp = u - fb / h.zbuf[k];
			if (xp > minXp)
				out.depthMm[k] = 0;
			else
				minXp = xp;
		}
	}
}

void Renderer::depthHoles(Rng& rng, RenderedFrame& out) const
{
	const int W = cam_.width, H = cam_.height, N = W * H;
	const int nHoles = int(std::lround(depth_.holesPerMpx * N * 1e-6));
	const double rMax = depth_.holeRadiusPx * W / 640.0;
	for (int h = 0; h < nHoles; h++)
	{
		const double hu = rng.uniform(0, W), hv = rng.uniform(0, H);
		const double r = rng.uniform(0.5, std::max(0.5, rMax));
		for (int v = std::max(0, int(hv - r));
		     v <= std::min(H - 1, int(hv + r)); v++)
			for (int u = std::max(0, int(hu - r));
			     u <= std::min(W - 1, int(hu + r)); u++)
				if ((u - hu) * (u - hu) + (v - hv) * (v - hv) <= r * r)
					out.depthMm[v * W + u] = 0;
	}
}

void Renderer::render(const Scene& scene, double t, const Eigen::Matrix3d& R_WC,
                      const Eigen::Vector3d& p_WC, uint64_t seed,
                      uint64_t frameIndex, RenderedFrame& out) const
{
	const int W = cam_.width, H = cam_.height, N = W * H;
	out.width = W;
	out.height = H;
	out.depthTrue.assign(N, 0.f);
	out.depthMm.assign(N, 0);
	out.rgb.assign(3 * size_t(N), 0);
	out.mask.assign(N, 0);
	out.objectId.assign(N, 0);

	const std::vector<Primitive> prims = scene.primitivesAt(t);
	const size_t P = prims.size();
	Hits h{std::vector<Eigen::Matrix3d>(P), std::vector<Eigen::Vector3d>(P),
	       std::vector<double>(N, std::numeric_limits<double>::infinity()),
	       std::vector<int16_t>(N, -1)};
	nearestHits(prims, R_WC, p_WC, h);
	Rng rng(seed, 0x5EED0000ULL + frameIndex);
	shadeAndSense(prims, h, R_WC, rng, out);
	if (depth_.projectorBaseline > 0) projectorShadows(h, out);
	depthHoles(rng, out);
}

}  // namespace bims::sim
