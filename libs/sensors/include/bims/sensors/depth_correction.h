// The depth correction of a real depth sensor as it is applied to the
// readings: Kinect-type sensors read depth too short towards the image
// borders (by 1.5-4 % on the Bonn recordings), which bends every plane and
// biases any alignment of two frames seen from different places. The model
// is a smooth multiplicative map
//     z_true = z (1 + delta(x, y)),  x = (u - cx) / fx,  y = (v - cy) / fy,
// with delta a polynomial of 12 terms (x, y, x^2, xy, y^2, x^3, x^2 y,
// x y^2, y^3, x^4, y^4, x^2 y^2) and no constant: the image centre reads
// right, a global scale is the sensor's depth unit. Its parameters are the
// [depth_correction] section (bims/sensors/params.h), fitted by
// bims-calib-depth (bims/ego/depth_correction.h: estimateDepthCorrection);
// every program applies it to the range images as they are read.
#pragma once

#include <bims/sensors/params.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <array>

namespace bims::sensors
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

}  // namespace bims::sensors
