// The fit of the depth correction (the model and its application:
// bims/sensors/depth_correction.h).
//
// estimateDepthCorrection() fits it to a stretch of a static scene with
// known (or estimated) poses: point-to-plane residuals between pairs of
// frames a few tenths of a second apart, robust (Huber) least squares.
// bims-calib-depth writes the result as the [depth_correction] section
// that every program applies to the range images as they are read.
#pragma once

#include <bims/ego/params.h>
#include <bims/ego/rgbd_input.h>
#include <bims/sensors/depth_correction.h>

#include <Eigen/Core>
#include <vector>

namespace bims::ego
{
using sensors::DepthCorrection;
using sensors::depthCorrectionBasis;
using sensors::depthCorrectionDelta;

/** Options of the fit. */
struct DepthFitOptions
{
	int min_gap = 9;              ///< frame pairs at least this far apart
	int max_gap = 40;             ///< ... and at most this far
	int step = 3;                 ///< every step-th frame is used
	int samples_per_pair = 4000;  ///< random pixels per pair (fixed seed)
	int iterations = 5;           ///< Gauss-Newton / IRLS rounds
	double huber_m = 0.02;        ///< Huber scale of the residuals [m]
	double min_depth_m = 0.3, max_depth_m = 6.0;
};

/** What the fit found. */
struct DepthFitResult
{
	DepthCorrectionParams params;
	int pairs = 0;
	size_t residuals = 0;     ///< in the last round
	double rms_before_m = 0;  ///< robust RMS point-to-plane residual
	double rms_after_m = 0;
	/** delta at the centre of the left, right, top and bottom borders and
	 * at the top-left corner (for the report). */
	double left = 0, right = 0, top = 0, bottom = 0, corner = 0;
};

/** Fits the correction to \a frames of a static scene (registered RGB-D
 * with their intrinsics) at camera poses \a T_WC (same order). Throws
 * std::invalid_argument when the sizes disagree or no pair qualifies. */
DepthFitResult estimateDepthCorrection(const std::vector<RgbdFrame>& frames,
                                       const std::vector<Eigen::Matrix4d>& T_WC,
                                       const DepthFitOptions& o = {});

}  // namespace bims::ego
