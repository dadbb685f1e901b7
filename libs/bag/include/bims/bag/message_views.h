// The ROS messages bims reads, as views of their serialized bytes, whatever
// their wire format (ROS 1's serialization or ROS 2's CDR): what the bag
// import (src/messages.h) and the ROS 2 node (libs/ros2) read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace bims::bag
{
/** A sensor_msgs/Image read in place: its fields, and its pixels where
 * they are in the recording's bytes (not copied). */
struct ImageView
{
	double t = 0;  ///< its header stamp [s]
	uint32_t height = 0, width = 0, step = 0;
	std::string encoding;
	bool bigEndian = false;
	const uint8_t* data = nullptr;
	size_t size = 0;
	/** Bytes after the message's data (ROS 1): librealsense's recorder
	 * appends its depth units there (a float32) in its newer versions. */
	const uint8_t* tail = nullptr;
	size_t tailSize = 0;
};

/** A sensor_msgs/CompressedImage read in place. */
struct CompressedView
{
	double t = 0;  ///< its header stamp [s]
	std::string format;
	const uint8_t* data = nullptr;
	size_t size = 0;
};

/** What the import reads of a sensor_msgs/CameraInfo. */
struct CameraInfoView
{
	uint32_t width = 0, height = 0;
	std::string distortionModel;
	std::vector<double> D;
	double K[9] = {};
};

/** A geometry_msgs/Transform: translation, then the rotation's quaternion
 * x y z w, as they are (not checked: the caller says what is wrong). */
struct TransformView
{
	double t[3] = {}, q[4] = {};
};
}  // namespace bims::bag
