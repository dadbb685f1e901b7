// Depth correction of a real depth sensor: Kinect-type sensors read depth
// too short towards the image borders (by 1.5-4 % on the Bonn recordings),
// which bends every plane and biases any alignment of two frames seen from
// different places. The model is a smooth multiplicative map
//     z_true = z (1 + delta(x, y)),  x = (u - cx) / fx,  y = (v - cy) / fy,
// with delta a polynomial of 12 terms (x, y, x^2, xy, y^2, x^3, x^2 y,
// x y^2, y^3, x^4, y^4, x^2 y^2) and no constant: the image centre reads
// right, a global scale is the sensor's depth unit.
//
// estimateDepthCorrection() fits it to a stretch of a static scene with
// known (or estimated) poses: point-to-plane residuals between pairs of
// frames a few tenths of a second apart, robust (Huber) least squares.
// bims-calib-depth writes the result as the [depth_correction] section
// that every program applies to the range images as they are read.
#pragma once

#include <bims/ego/params.h>
#include <bims/ego/rgbd_input.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <array>
#include <string>
#include <vector>

namespace bims::ego
{
/** The polynomial's terms at normalised image coordinates (x, y). */
std::array<double, kDepthCorrectionTerms> depthCorrectionBasis(double x,
                                                               double y);

/** delta(x, y) = sum c_i term_i(x, y): the correction at normalised image
 * coordinates (z_true = z (1 + delta)). */
double depthCorrectionDelta(const DepthCorrectionParams& p, double x, double y);

/** Applies a correction; keeps the per-pixel factors of the last camera. */
class DepthCorrection
{
 public:
	explicit DepthCorrection(const DepthCorrectionParams& p = {}) : p_(p) {}
	bool enabled() const { return p_.enable; }
	/** 1 + delta(x, y) for every pixel (CV_32FC1), cached per K and size. */
	const cv::Mat& factors(const Eigen::Matrix3d& K, cv::Size size);
	/** Corrects a metric depth image (CV_32FC1) in place. */
	void apply(cv::Mat& depth, const Eigen::Matrix3d& K);
	/** Corrects the observation's range image in place (intrinsics:
	 * intrinsicsOf()). Does nothing when disabled or without usable
	 * intrinsics (rgbdFrameFrom() reports those). */
	void apply(mrpt::obs::CObservation3DRangeScan& obs,
	           const CameraParams& cam);

 private:
	DepthCorrectionParams p_;
	Eigen::Matrix3d K_ = Eigen::Matrix3d::Zero();
	cv::Mat f_;
};

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
