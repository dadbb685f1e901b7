#include <bims/sim/scene.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bims::sim
{
namespace
{
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEps = 1e-9;

/** Slab test: entry and exit ray parameters of an axis-aligned box. */
bool slabs(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
           const Eigen::Vector3d& h, double& tNear, double& tFar)
{
	tNear = -kInf;
	tFar = kInf;
	for (int i = 0; i < 3; i++)
	{
		if (std::abs(d[i]) < 1e-15)
		{
			if (o[i] < -h[i] || o[i] > h[i]) return false;
			continue;
		}
		const double inv = 1.0 / d[i];
		double t1 = (-h[i] - o[i]) * inv, t2 = (h[i] - o[i]) * inv;
		if (t1 > t2) std::swap(t1, t2);
		tNear = std::max(tNear, t1);
		tFar = std::min(tFar, t2);
		if (tNear > tFar) return false;
	}
	return true;
}
}  // namespace

double intersectLocal(const Primitive& p, const Eigen::Vector3d& o,
                      const Eigen::Vector3d& d)
{
	switch (p.shape)
	{
		case Shape::Box:
		{
			double tn, tf;
			if (!slabs(o, d, p.half, tn, tf)) return kInf;
			if (tn > kEps) return tn;
			return kInf;  // camera inside or box behind: not visible
		}
		case Shape::Room:
		{
			double tn, tf;
			if (!slabs(o, d, p.half, tn, tf)) return kInf;
			return tf > kEps ? tf : kInf;
		}
		case Shape::Sphere:
		{
			const double r = p.half.x();
			const double a = d.squaredNorm();
			const double b = o.dot(d);
			const double c = o.squaredNorm() - r * r;
			const double disc = b * b - a * c;
			if (disc < 0) return kInf;
			const double t = (-b - std::sqrt(disc)) / a;
			return t > kEps ? t : kInf;
		}
	}
	return kInf;
}

SurfaceHit surfaceAt(const Primitive& p, const Eigen::Vector3d& x)
{
	SurfaceHit h;
	if (p.shape == Shape::Sphere)
	{
		const double r = p.half.x();
		const Eigen::Vector3d n = x.normalized();
		h.n_W = p.R_WP * n;
		h.s = r * std::atan2(n.y(), n.x());
		h.t = r * std::acos(std::clamp(n.z(), -1.0, 1.0));
		h.face = 0;
		return h;
	}
	// Box / room: the face is the axis where |x_i| / h_i is largest.
	int ax = 0;
	double best = -1;
	for (int i = 0; i < 3; i++)
	{
		const double r = std::abs(x[i]) / p.half[i];
		if (r > best)
		{
			best = r;
			ax = i;
		}
	}
	const double sgn = x[ax] >= 0 ? 1.0 : -1.0;
	Eigen::Vector3d n = Eigen::Vector3d::Zero();
	n[ax] = p.shape == Shape::Room ? -sgn : sgn;
	h.n_W = p.R_WP * n;
	const int a1 = (ax + 1) % 3, a2 = (ax + 2) % 3;
	h.s = x[a1] + p.half[a1];
	h.t = x[a2] + p.half[a2];
	h.face = 2 * ax + (sgn > 0 ? 1 : 0);
	return h;
}

double distanceToSurface(const Primitive& p, const Eigen::Vector3d& x_W)
{
	const Eigen::Vector3d x = p.R_WP.transpose() * (x_W - p.t_WP);
	if (p.shape == Shape::Sphere) return std::abs(x.norm() - p.half.x());
	const Eigen::Vector3d q = x.cwiseAbs() - p.half;
	const double outside = q.cwiseMax(0.0).norm();
	const double inside = std::min(q.maxCoeff(), 0.0);
	return std::abs(outside + inside);
}

std::vector<Primitive> Scene::primitivesAt(double t) const
{
	std::vector<Primitive> out = staticPrims;
	for (size_t k = 0; k < objects.size(); k++)
		objects[k]->primitives(t, int(k) + 1, out);
	return out;
}

double Scene::distanceToNearestSurface(const Eigen::Vector3d& x_W,
                                       double t) const
{
	double best = kInf;
	for (const auto& p : primitivesAt(t))
		best = std::min(best, distanceToSurface(p, x_W));
	return best;
}

}  // namespace bims::sim
