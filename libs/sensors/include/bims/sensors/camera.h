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

}  // namespace bims::sensors
