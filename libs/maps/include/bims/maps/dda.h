// 3D DDA voxel traversal of a segment (free-space ray casting).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdlib>

namespace bims::maps
{
/** One axis of the DDA of traverseRay(): from coordinate \a a0 in voxel
 * \a i towards \a b0, the step \a s (-1, 0, 1), the parameter \a tMax of
 * the next voxel boundary and \a tDelta, the parameter per voxel. Every
 * walker of the rays starts from these values, so that they take the same
 * steps. */
inline void ddaAxisSetup(double a0, double b0, int32_t i, int32_t& s,
                         double& tMax, double& tDelta)
{
	const double d = b0 - a0;
	if (d > 0)
	{
		s = 1;
		tDelta = 1 / d;
		tMax = (i + 1 - a0) * tDelta;
	}
	else if (d < 0)
	{
		s = -1;
		tDelta = -1 / d;
		tMax = (a0 - i) * tDelta;
	}
	else
	{
		s = 0;
		tDelta = tMax = INFINITY;
	}
}

/** Visits the voxels a segment crosses, from the voxel of \a a (in voxel
 * units) up to but excluding the voxel of \a b (Amanatides & Woo 3D DDA,
 * 6-connected, the same traversal as OctoMap's computeRayKeys). Exactly
 * |dx|+|dy|+|dz| voxels are visited (the voxel differences of a and b). */
template <class Visit>
inline void traverseRay(const double a[3], const double b[3], Visit&& visit)
{
	int32_t x = int32_t(std::floor(a[0])), y = int32_t(std::floor(a[1])),
	        z = int32_t(std::floor(a[2]));
	const int32_t ex = int32_t(std::floor(b[0])),
	              ey = int32_t(std::floor(b[1])),
	              ez = int32_t(std::floor(b[2]));
	uint32_t n =
	    uint32_t(std::abs(ex - x) + std::abs(ey - y) + std::abs(ez - z));
	if (n == 0) return;
	int32_t sx, sy, sz;
	double tx, ty, tz, dx, dy, dz;
	ddaAxisSetup(a[0], b[0], x, sx, tx, dx);
	ddaAxisSetup(a[1], b[1], y, sy, ty, dy);
	ddaAxisSetup(a[2], b[2], z, sz, tz, dz);
	while (n--)
	{
		visit(x, y, z);
		// Branch-free choice of the axis whose boundary comes first (the
		// choice is data dependent and mispredicts often as a branch).
		const bool bx = (tx < ty) & (tx < tz);
		const bool by = !bx & (ty < tz);
		const bool bz = !bx & !by;
		x += bx ? sx : 0;
		y += by ? sy : 0;
		z += bz ? sz : 0;
		tx += bx ? dx : 0.0;
		ty += by ? dy : 0.0;
		tz += bz ? dz : 0.0;
	}
}

}  // namespace bims::maps
