// The RealSense SDK's own recordings (librealsense's "ROS file format", as
// RealSense Viewer and rs-record write it): a ROS 1 bag whose streams are
// /device_D/sensor_S/<Stream>_I/... (rsSdkTopics() in bag_import.h finds
// them by name), each with its extrinsics from a reference stream
// (.../tf/N, geometry_msgs/Transform). Its depth is in the depth camera,
// not registered to the colour camera: registerDepth() puts it there, as
// librealsense's align and realsense-ros's align_depth do
// (docs/import-bag.md, "RealSense SDK recordings").
#pragma once

#include <bims/bag/bag_import.h>
#include <mrpt/img/TCamera.h>

#include <opencv2/core.hpp>
#include <string>

#include "messages.h"

namespace bims::bag
{
/** The rigid transform of a tf message; throws std::runtime_error saying
 * what is wrong when a value is not finite or the quaternion is not a
 * rotation (its norm not within 1e-3 of 1; else it is normalised). */
RigidTransform rigidTransformOf(const TransformView& v);

/** b after a: p -> b(a(p)). */
RigidTransform compose(const RigidTransform& b, const RigidTransform& a);
/** The inverse transform. */
RigidTransform inverse(const RigidTransform& a);

/** The 16-bit depth image \a depth (\a metresPerUnit) of camera
 * \a depthCam seen from the camera \a colourCam, \a depthToColour apart:
 * a CV_32FC1 image of colourCam's size in metres, 0 where no depth lands.
 * Each depth pixel's square (its corners at +-0.5 px) is projected at its
 * depth and fills the colour pixels whose centres it covers, the nearest
 * depth kept where several land. With the same camera and the identity,
 * every pixel is its own, its depth exactly. */
cv::Mat registerDepth(const cv::Mat& depth, double metresPerUnit,
                      const mrpt::img::TCamera& depthCam,
                      const mrpt::img::TCamera& colourCam,
                      const RigidTransform& depthToColour);

}  // namespace bims::bag
