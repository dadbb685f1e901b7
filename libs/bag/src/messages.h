// The messages bims reads, whatever their wire format: a ROS 1 message
// (ROS's serialization, read by Debian's generated classes behind the guard
// of bag_guard.h) or a ROS 2 one (CDR, read by cdr.h). bag_import.cpp reads
// only these views: one home for each rule of the import, for every format.
#pragma once

#include <bims/bag/bag_import.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "message_source.h"

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
/** geometry_msgs/Transform: translation, then the rotation's quaternion
 * x y z w, as they are (not checked: the caller says what is wrong). */
struct TransformView
{
	double t[3] = {}, q[4] = {};
};
TransformView readTransform(const BagConnection& c, const uint8_t* p, size_t n);

}  // namespace bims::bag
