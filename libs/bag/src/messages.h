// The messages bims reads, whatever their wire format: a ROS 1 message
// (ROS's serialization, read by Debian's generated classes behind the guard
// of bag_guard.h) or a ROS 2 one (CDR, read by cdr.h). bag_import.cpp reads
// only these views: one home for each rule of the import, for every format.
#pragma once

#include <bims/bag/bag_import.h>
#include <bims/bag/message_views.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "message_source.h"

namespace bims::bag
{
/** The message types the import reads. */
enum class MessageKind
{
	Image,
	CompressedImage,
	CameraInfo,
	Imu,
	MagneticField,
	Float32,    ///< std_msgs/Float32 (the RealSense SDK's option values)
	Transform,  ///< geometry_msgs/Transform (the RealSense SDK's tf)
	Other
};

/** The kind of \a type, a ROS 1 ("sensor_msgs/Image") or ROS 2
 * ("sensor_msgs/msg/Image") type name. */
MessageKind messageKind(const std::string& type);

/** \a type without ROS 2's "/msg/": "sensor_msgs/msg/Image" is
 * "sensor_msgs/Image", the name the import's rules use. */
std::string baseType(const std::string& type);

/** A sample of a sensor_msgs/Imu: a quantity whose covariance's first
 * element is -1 is "not measured" (the message's convention). */
ImuSample imuSampleOf(double t, const double w[3], double wCov0,
                      const double a[3], double aCov0);

/** A sensor_msgs/MagneticField's sample: tesla to gauss (MRPT's unit). */
ImuSample magSampleOf(double t, const double m[3]);

/** Each reads the serialized message \a p (\a n bytes) of connection \a c,
 * every length checked against its bytes; throws std::runtime_error
 * saying what is wrong (the connection unreadable, another type, a message
 * shorter than its type, an array longer than the message). */
double headerStamp(const BagConnection& c, const uint8_t* p, size_t n);
ImageView readImage(const BagConnection& c, const uint8_t* p, size_t n);
CompressedView readCompressed(const BagConnection& c, const uint8_t* p,
                              size_t n);
CameraInfoView readCameraInfo(const BagConnection& c, const uint8_t* p,
                              size_t n);
ImuSample readImu(const BagConnection& c, const uint8_t* p, size_t n);
ImuSample readMagneticField(const BagConnection& c, const uint8_t* p, size_t n);
float readFloat32(const BagConnection& c, const uint8_t* p, size_t n);
TransformView readTransform(const BagConnection& c, const uint8_t* p, size_t n);

}  // namespace bims::bag
