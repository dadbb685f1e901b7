// A walk over a ROS 1 bag's records (format 2.0) before Debian's
// rosbag_storage opens it: rosbag trusts the lengths a file declares and
// allocates them (a record header declaring 4 GB is allocated before
// anything is read), so every length is checked here against the bytes
// the file holds (docs/fuzz.md, "bag").
#pragma once

#include <rosbag/message_instance.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace bims::bag
{
/** Checks the records of the bag \a path: each record's header and data
 * lengths within the file (inside an uncompressed chunk: within the
 * chunk), each header's fields within the header, a chunk's uncompressed
 * size (its own length when uncompressed; at most 1 GiB), the bag header's
 * index position within the file and its connection and chunk counts not
 * beyond the records at that position, index records' entry counts within
 * their data. Throws std::runtime_error saying what is wrong and at which
 * byte (not naming the file: the caller does), or that the format is not
 * 2.0. A file whose first line is no bag's version line (rosbag's
 * "#ROS<word> V<major>.<minor>") is left to rosbag, which refuses it. */
void checkBagRecords(const std::string& path);

/** The messages whose variable-length arrays ROS's deserializer sizes
 * before reading them. */
enum class ArrayMessage
{
	Image,            ///< sensor_msgs/Image: data
	CompressedImage,  ///< sensor_msgs/CompressedImage: data
	CameraInfo        ///< sensor_msgs/CameraInfo: D
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

/** Checks that every string and array the serialized message \a bytes of
 * kind \a kind declares is within its \a n bytes; throws
 * std::runtime_error saying which is not. */
void checkMessageArrays(const uint8_t* bytes, size_t n, ArrayMessage kind);

/** The message \a m as a \a M (an Image, CompressedImage or CameraInfo),
 * null when the bag says it is another type (as rosbag's instantiate). ROS's
 * deserializer resizes a vector to the length a message declares before
 * reading it (a few bytes declaring 1.9 GB were allocated: fuzz finding
 * oom-compressed-image-data-length): the message's bytes are read first,
 * their arrays checked (checkMessageArrays), then deserialized. */
template <typename M>
boost::shared_ptr<M> readMessage(const rosbag::MessageInstance& m)
{
	if (!m.isType<M>()) return nullptr;
	constexpr uint32_t kMaxMessage = uint32_t{1} << 30;  // as a chunk
	const uint32_t n = m.size();
	if (n > kMaxMessage)
		throw std::runtime_error("a message of " + std::to_string(n) +
		                         " bytes, beyond 1 GiB");
	std::vector<uint8_t> bytes(n);
	ros::serialization::OStream out(bytes.data(), n);
	m.write(out);
	checkMessageArrays(bytes.data(), n, arrayMessage(static_cast<M*>(nullptr)));
	auto msg = boost::make_shared<M>();
	ros::serialization::IStream in(bytes.data(), n);
	ros::serialization::deserialize(in, *msg);
	return msg;
}

}  // namespace bims::bag
