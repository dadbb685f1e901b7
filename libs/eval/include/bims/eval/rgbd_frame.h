// What the RGB-D importers (bims-import-tum, bims-import-stray) share: a
// depth PNG read and checked, a 16-bit depth image made into the rawlog's
// observation, and the registered colour image attached to it. One home for
// each conversion: the importers differ only in where the images and their
// stamps come from.
#pragma once

#include <bims/io/image_file.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <opencv2/core.hpp>

#include <string>

namespace bims::eval
{
/** Reads the depth PNG \a path as it is stored: throws std::runtime_error
 * naming the file when it cannot be read or is not a 16-bit single-channel
 * image. */
cv::Mat readDepthPng(const std::string& path, const ImageLimits& limits = {});

/** The observation of one registered depth image:
 * \a depth (CV_16UC1, 0 = no reading; or CV_32FC1, where 0, negative and
 * non-finite values are no reading) times \a metresPerUnit is metres;
 * the range image holds it in units of \a rangeUnits metres (rounded; a
 * value beyond 65535 units becomes 0, no reading), range_is_depth,
 * sensorPose identity, cameraParams and cameraParamsIntensity \a camera,
 * label \a label, stamp \a t [s] (mrpt::Clock::fromDouble). No intensity
 * image (attachColour adds one). Throws std::invalid_argument when \a depth
 * is not CV_16UC1 nor CV_32FC1, or not of the camera's size. */
mrpt::obs::CObservation3DRangeScan::Ptr depthObservation(
    const cv::Mat& depth, double metresPerUnit,
    const mrpt::img::TCamera& camera, const std::string& label, double t,
    double rangeUnits);

/** Attaches \a bgr (8-bit, 3 channels BGR, registered to the depth image
 * and of its size) as the observation's intensity image: CH_VISIBLE, deep
 * copy, relativePoseIntensityWRTDepth the rotation between MRPT's 3D-scan
 * axes and the optical axes (the same camera). Throws
 * std::invalid_argument when the size or type differs. */
void attachColour(mrpt::obs::CObservation3DRangeScan& obs, const cv::Mat& bgr);

/** An IMU sample as the rawlog's observation, label \a label, stamp \a t
 * [s]: of the gyro [rad/s], the specific force [m/s^2] and the magnetic
 * field [gauss], those given (nullptr: not measured; each 3 values, the
 * IMU's x y z). */
mrpt::obs::CObservationIMU::Ptr imuObservation(const std::string& label,
                                               double t, const double* gyro,
                                               const double* accel,
                                               const double* mag);

/** [sensors] rgbd_label, imu_label of an importer's .ini into \a rgbdLabel,
 * \a imuLabel (strict: other keys are errors, but the informative
 * rgbd_rate_hz and imu_rate_hz of bims-sim's calibration.ini). An empty
 * value, "any" to the readers of a rawlog, keeps the label given. */
void loadImportLabels(const mrpt::config::CConfigFileBase& cfg,
                      std::string& rgbdLabel, std::string& imuLabel);

}  // namespace bims::eval
