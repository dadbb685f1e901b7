// A tiny ray caster of axis-aligned boxes for the maps tests (the project's
// simulator, libs/sim, is written in parallel; these tests stay independent
// of it). Renders CObservation3DRangeScan depth images (uint16 mm).
#pragma once

#include <mrpt/math/TPoint3D.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/poses/CPose3D.h>

#include <vector>

namespace bims::maps::test
{
struct Box
{
	mrpt::math::TPoint3D lo, hi;
};

/** A closed room [-4, 4] x [-4, 4] x [0, 3] m made of 10 cm thick boxes. */
std::vector<Box> room();

/** Renders the depth seen from the scan frame {S} at T_WS (x forward, y
 * left, z up) by a W x H pinhole camera with horizontal field of view
 * \a hfovDeg. Pixels with no hit have depth 0. Timestamp = \a frame. */
mrpt::obs::CObservation3DRangeScan::Ptr renderScan(
    const std::vector<Box>& scene, const mrpt::poses::CPose3D& T_WS, int W,
    int H, double hfovDeg, int frame);

}  // namespace bims::maps::test
