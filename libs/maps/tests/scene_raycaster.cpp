#include "scene_raycaster.h"

#include <bims/common/frames.h>

#include <mrpt/core/Clock.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bims::maps::test
{
std::vector<Box> room()
{
	const double t = 0.1;
	return {{{-4, -4, -t}, {4, 4, 0}},       // floor
	        {{-4, -4, 3}, {4, 4, 3 + t}},    // ceiling
	        {{4, -4, 0}, {4 + t, 4, 3}},     // +x wall
	        {{-4 - t, -4, 0}, {-4, 4, 3}},   // -x wall
	        {{-4, 4, 0}, {4, 4 + t, 3}},     // +y wall
	        {{-4, -4 - t, 0}, {4, -4, 3}}};  // -y wall
}

namespace
{
// Slab test: entry distance of the ray o + t d into the box, or +inf.
double hitBox(const Box& b, const double o[3], const double d[3])
{
	double t0 = 0, t1 = std::numeric_limits<double>::infinity();
	const double lo[3] = {b.lo.x, b.lo.y, b.lo.z},
	             hi[3] = {b.hi.x, b.hi.y, b.hi.z};
	for (int k = 0; k < 3; ++k)
	{
		if (std::abs(d[k]) < 1e-12)
		{
			if (o[k] < lo[k] || o[k] > hi[k])
				return std::numeric_limits<double>::infinity();
			continue;
		}
		double a = (lo[k] - o[k]) / d[k], c = (hi[k] - o[k]) / d[k];
		if (a > c) std::swap(a, c);
		t0 = std::max(t0, a);
		t1 = std::min(t1, c);
		if (t0 > t1) return std::numeric_limits<double>::infinity();
	}
	return t0;
}
}  // namespace

mrpt::obs::CObservation3DRangeScan::Ptr renderScan(
    const std::vector<Box>& scene, const mrpt::poses::CPose3D& T_WS, int W,
    int H, double hfovDeg, int frame)
{
	auto o = mrpt::obs::CObservation3DRangeScan::Create();
	o->sensorLabel = "TEST_RGBD";
	o->timestamp = mrpt::Clock::time_point(
	    mrpt::Clock::duration(1000000000LL + frame * 333333LL));
	o->hasRangeImage = true;
	o->range_is_depth = true;
	o->rangeUnits = 0.001f;
	o->maxRange = 10;
	o->rangeImage_setSize(H, W);
	const double f = (W / 2.0) / std::tan(hfovDeg * M_PI / 360);
	const double cx = (W - 1) / 2.0, cy = (H - 1) / 2.0;
	o->cameraParams.ncols = W;
	o->cameraParams.nrows = H;
	o->cameraParams.setIntrinsicParamsFromValues(f, f, cx, cy);
	o->cameraParamsIntensity = o->cameraParams;
	const auto T_WC = T_WS + bims::T_SC();
	const auto& R = T_WC.getRotationMatrix();
	const double org[3] = {T_WC.x(), T_WC.y(), T_WC.z()};
	for (int v = 0; v < H; ++v)
		for (int u = 0; u < W; ++u)
		{
			const double dc[3] = {(u - cx) / f, (v - cy) / f, 1};
			double d[3];
			for (int r = 0; r < 3; ++r)
				d[r] = R(r, 0) * dc[0] + R(r, 1) * dc[1] + R(r, 2) * dc[2];
			double best = std::numeric_limits<double>::infinity();
			for (const auto& b : scene)
				best = std::min(best, hitBox(b, org, d));
			// d has unit optical-axis component: best is the depth.
			o->rangeImage(v, u) = std::isfinite(best) && best < 60
			                          ? uint16_t(std::lround(best * 1000))
			                          : 0;
		}
	return o;
}

}  // namespace bims::maps::test
