// The messages of a bag read safely: ROS's deserializer resizes a vector to
// the length a message declares before reading it (a few bytes declaring
// 1.9 GB were allocated: fuzz finding oom-compressed-image-data-length), so
// every string and array is checked against the message's bytes first
// (docs/fuzz.md, "bag"). The bag's records are checked as they are read
// (bag_file.h).
#pragma once

#include <ros/serialization.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>

#include <boost/make_shared.hpp>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "messages.h"

namespace bims::bag
{
/** The messages whose variable-length arrays ROS's deserializer sizes
 * before reading them. */
enum class ArrayMessage
{
	Image,            ///< sensor_msgs/Image: data
	CompressedImage,  ///< sensor_msgs/CompressedImage: data
	CameraInfo,       ///< sensor_msgs/CameraInfo: D
	/** Imu, MagneticField: no array; their header's frame_id is a string,
	 * which the deserializer checks before reading */
	HeaderOnly
};
inline ArrayMessage arrayMessage(const sensor_msgs::Image*)
{
	return ArrayMessage::Image;
}
inline ArrayMessage arrayMessage(const sensor_msgs::CompressedImage*)
{
	return ArrayMessage::CompressedImage;
}
inline ArrayMessage arrayMessage(const sensor_msgs::CameraInfo*)
{
	return ArrayMessage::CameraInfo;
}
inline ArrayMessage arrayMessage(const sensor_msgs::Imu*)
{
	return ArrayMessage::HeaderOnly;
}
inline ArrayMessage arrayMessage(const sensor_msgs::MagneticField*)
{
	return ArrayMessage::HeaderOnly;
}

/** Checks that every string and array the serialized message \a bytes of
 * kind \a kind declares is within its \a n bytes; throws
 * std::runtime_error saying which is not. */
void checkMessageArrays(const uint8_t* bytes, size_t n, ArrayMessage kind);

/** \a md5, a connection's MD5 sum, is \a M's (or "*": any). */
template <typename M>
bool isType(const std::string& md5)
{
	return md5 == "*" || md5 == ros::message_traits::md5sum<M>();
}

/** The serialized sensor_msgs/Image \a bytes (\a n of them), every length
 * checked against them; throws std::runtime_error saying which is not. */
ImageView imageView(const uint8_t* bytes, size_t n);

/** The serialized sensor_msgs/CompressedImage \a bytes (\a n of them)
 * read in place, every length checked against them. */
CompressedView compressedView(const uint8_t* bytes, size_t n);

/** The serialized message \a bytes (\a n of them) as a \a M: its arrays
 * checked (checkMessageArrays), then deserialized from the bag's bytes,
 * not copied first. */
template <typename M>
boost::shared_ptr<M> readMessage(const uint8_t* bytes, size_t n)
{
	checkMessageArrays(bytes, n, arrayMessage(static_cast<M*>(nullptr)));
	auto msg = boost::make_shared<M>();
	// (IStream takes its bytes as not const; it only reads them)
	ros::serialization::IStream in(const_cast<uint8_t*>(bytes),
	                               static_cast<uint32_t>(n));
	ros::serialization::deserialize(in, *msg);
	return msg;
}

}  // namespace bims::bag
