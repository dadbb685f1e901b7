// ROS 2's messages as CDR (OMG's Common Data Representation, XCDR1 as
// ROS 2's middlewares write it), read by a guarded decoder of our own: the
// 4-byte encapsulation header (CDR_LE or CDR_BE), then the fields, each
// primitive aligned to its size (at most 8) from the end of that header;
// a string is its length (with its terminating NUL) and bytes, a sequence
// its count and elements. Every length is checked against the bytes left
// before anything is allocated; a message shorter than its type is an
// error saying which field it ends in (docs/import-bag.md, "ROS 2").
// One decoder for the bags (src/messages.h) and the live node (libs/ros2).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <bims/bag/bag_import.h>
#include <bims/bag/message_views.h>

namespace bims::bag::cdr
{
/** The header's stamp of a message that starts with a std_msgs/Header
 * (builtin_interfaces/Time, then frame_id), as every message read does. */
double headerStamp(const uint8_t* p, size_t n);
/** A header's stamp as it is on the wire (a time before 1970 or
 * nanoseconds >= 1e9 are errors). */
struct HeaderTime
{
	uint32_t sec = 0, nsec = 0;
};
/** The header's stamp of a message that starts with a std_msgs/Header, as
 * it is (headerStamp() is it in seconds). */
HeaderTime headerTime(const uint8_t* p, size_t n);
/** sensor_msgs/msg/Image: its data in place. */
ImageView image(const uint8_t* p, size_t n);
/** sensor_msgs/msg/CompressedImage: its data in place. */
CompressedView compressedImage(const uint8_t* p, size_t n);
/** sensor_msgs/msg/CameraInfo, read whole (d, k, r, p, binning, roi). */
CameraInfoView cameraInfo(const uint8_t* p, size_t n);
/** sensor_msgs/msg/Imu, read whole. */
ImuSample imu(const uint8_t* p, size_t n);
/** sensor_msgs/msg/MagneticField, read whole. */
ImuSample magneticField(const uint8_t* p, size_t n);
/** std_msgs/msg/Float32. */
float float32(const uint8_t* p, size_t n);
/** geometry_msgs/msg/Transform. */
TransformView transform(const uint8_t* p, size_t n);

}  // namespace bims::bag::cdr
