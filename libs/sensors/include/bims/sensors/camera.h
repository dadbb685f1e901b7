// The camera model of a scan: the intrinsics its range image is read with.
#pragma once

#include <bims/sensors/params.h>

#include <mrpt/img/TCamera.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <Eigen/Core>

#include <string>

namespace bims::sensors
{
/** The intrinsics of \a obs's range image: \a cam when given (its size
 * must match), else the observation's cameraParams. \return empty string
 * on success, else what is wrong. */
std::string intrinsicsOf(const mrpt::obs::CObservation3DRangeScan& obs,
                         const CameraParams& cam, Eigen::Matrix3d& K);

/** The field of view a camera's focal length may give on its image, along
 * each axis [deg]: an RGB-D sensor sees 40-120 degrees; outside these the
 * intrinsics are those of another image size or not a camera's. */
constexpr double kMinFieldOfViewDeg = 10, kMaxFieldOfViewDeg = 160;

/** Why \a c (fx fy cx cy of a width x height image) cannot be a camera of
 * that image; "" when it can. Refused: a size not positive, a value not
 * finite, a principal point outside the image (0 <= cx <= width, 0 <= cy
 * <= height are accepted), a focal length whose field of view along its
 * axis, 2 atan(size / (2 f)), is outside [kMinFieldOfViewDeg,
 * kMaxFieldOfViewDeg] (the message gives the focal lengths accepted). The
 * one check of intrinsics against an image size, for every importer. */
std::string intrinsicsProblem(const PinholeCamera& c);

/** Throws std::runtime_error "WHERE: PROBLEM" (intrinsicsProblem) when \a c
 * cannot be a camera of its image. \a where: whence the intrinsics come
 * (e.g. "camera_matrix.csv, scaled to the depth grid"). */
void checkIntrinsics(const PinholeCamera& c, const std::string& where);

}  // namespace bims::sensors
