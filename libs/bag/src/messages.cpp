#include "messages.h"

#include <geometry_msgs/Transform.h>
#include <mrpt/core/format.h>
#include <std_msgs/Float32.h>

#include <cstring>
#include <stdexcept>

#include <bims/bag/cdr.h>
#include "bag_guard.h"

namespace bims::bag
{
namespace
{
using std::runtime_error;

/** A ROS 1 message's connection's MD5 sum \a md5 must be \a M's: else an
 * error (fuzz finding ub-imu-of-another-md5: rosbag gave a null message
 * for it, which was read). */
template <typename M>
void checkMd5(const std::string& md5)
{
	if (!isType<M>(md5))
		throw runtime_error(std::string("not a ") +
		                    ros::message_traits::datatype<M>() +
		                    ": its MD5 sum " + md5 + " is another message's");
}

template <typename M>
boost::shared_ptr<M> read(const BagConnection& c, const uint8_t* p, size_t n)
{
	checkMd5<M>(c.md5);
	return readMessage<M>(p, n);
}

/** The stamp of a ROS 1 message that starts with a std_msgs/Header (seq,
 * stamp, frame_id), read without the rest. */
double ros1HeaderStamp(const uint8_t* p, size_t n)
{
	if (n < 12)
		throw runtime_error("it ends inside its header's stamp: corrupt");
	uint32_t sec = 0, nsec = 0;
	std::memcpy(&sec, p + 4, 4);
	std::memcpy(&nsec, p + 8, 4);
	return stampSeconds(sec, nsec);
}

/** The connection's messages can be read as \a kind. */
void check(const BagConnection& c, MessageKind kind)
{
	if (!c.unreadable.empty()) throw runtime_error(c.unreadable);
	if (messageKind(c.type) != kind)
		throw runtime_error("a " + c.type + ", not the type expected");
}
}  // namespace

std::string baseType(const std::string& type)
{
	const size_t k = type.find("/msg/");
	if (k == std::string::npos) return type;
	return type.substr(0, k) + type.substr(k + 4);
}

MessageKind messageKind(const std::string& type)
{
	const std::string t = baseType(type);
	if (t == "sensor_msgs/Image") return MessageKind::Image;
	if (t == "sensor_msgs/CompressedImage") return MessageKind::CompressedImage;
	if (t == "sensor_msgs/CameraInfo") return MessageKind::CameraInfo;
	if (t == "sensor_msgs/Imu") return MessageKind::Imu;
	if (t == "sensor_msgs/MagneticField") return MessageKind::MagneticField;
	if (t == "std_msgs/Float32") return MessageKind::Float32;
	if (t == "geometry_msgs/Transform") return MessageKind::Transform;
	return MessageKind::Other;
}

ImuSample imuSampleOf(double t, const double w[3], double wCov0,
                      const double a[3], double aCov0)
{
	ImuSample s;
	s.t = t;
	s.hasGyro = wCov0 != -1;
	s.hasAccel = aCov0 != -1;
	for (int k = 0; k < 3; k++)
	{
		s.w[k] = w[k];
		s.a[k] = a[k];
	}
	return s;
}

ImuSample magSampleOf(double t, const double m[3])
{
	ImuSample s;
	s.t = t;
	s.hasMag = true;
	// tesla to gauss (MRPT's IMU_MAG_* unit)
	for (int k = 0; k < 3; k++) s.m[k] = m[k] * 1e4;
	return s;
}

double headerStamp(const BagConnection& c, const uint8_t* p, size_t n)
{
	if (!c.unreadable.empty()) throw runtime_error(c.unreadable);
	return c.wire == Wire::Cdr ? cdr::headerStamp(p, n) : ros1HeaderStamp(p, n);
}

ImageView readImage(const BagConnection& c, const uint8_t* p, size_t n)
{
	check(c, MessageKind::Image);
	if (c.wire == Wire::Cdr) return cdr::image(p, n);
	checkMd5<sensor_msgs::Image>(c.md5);
	ImageView v = imageView(p, n);
	v.t = ros1HeaderStamp(p, n);
	return v;
}

CompressedView readCompressed(const BagConnection& c, const uint8_t* p,
                              size_t n)
{
	check(c, MessageKind::CompressedImage);
	if (c.wire == Wire::Cdr) return cdr::compressedImage(p, n);
	checkMd5<sensor_msgs::CompressedImage>(c.md5);
	return compressedView(p, n);
}

CameraInfoView readCameraInfo(const BagConnection& c, const uint8_t* p,
                              size_t n)
{
	check(c, MessageKind::CameraInfo);
	if (c.wire == Wire::Cdr) return cdr::cameraInfo(p, n);
	const auto m = read<sensor_msgs::CameraInfo>(c, p, n);
	CameraInfoView v;
	v.width = m->width;
	v.height = m->height;
	v.distortionModel = m->distortion_model;
	v.D = m->D;
	for (int k = 0; k < 9; k++) v.K[k] = m->K[k];
	return v;
}

ImuSample readImu(const BagConnection& c, const uint8_t* p, size_t n)
{
	check(c, MessageKind::Imu);
	if (c.wire == Wire::Cdr) return cdr::imu(p, n);
	const auto m = read<sensor_msgs::Imu>(c, p, n);
	const double w[3] = {m->angular_velocity.x, m->angular_velocity.y,
	                     m->angular_velocity.z};
	const double a[3] = {m->linear_acceleration.x, m->linear_acceleration.y,
	                     m->linear_acceleration.z};
	return imuSampleOf(stampSeconds(m->header.stamp.sec, m->header.stamp.nsec),
	                   w, m->angular_velocity_covariance[0], a,
	                   m->linear_acceleration_covariance[0]);
}

ImuSample readMagneticField(const BagConnection& c, const uint8_t* p, size_t n)
{
	check(c, MessageKind::MagneticField);
	if (c.wire == Wire::Cdr) return cdr::magneticField(p, n);
	const auto m = read<sensor_msgs::MagneticField>(c, p, n);
	const double v[3] = {m->magnetic_field.x, m->magnetic_field.y,
	                     m->magnetic_field.z};
	return magSampleOf(stampSeconds(m->header.stamp.sec, m->header.stamp.nsec),
	                   v);
}

float readFloat32(const BagConnection& c, const uint8_t* p, size_t n)
{
	check(c, MessageKind::Float32);
	if (c.wire == Wire::Cdr) return cdr::float32(p, n);
	checkMd5<std_msgs::Float32>(c.md5);
	if (n < 4)
		throw runtime_error(
		    mrpt::format("%zu bytes: shorter than a std_msgs/Float32", n));
	float v = 0;
	std::memcpy(&v, p, 4);
	return v;
}

TransformView readTransform(const BagConnection& c, const uint8_t* p, size_t n)
{
	check(c, MessageKind::Transform);
	if (c.wire == Wire::Cdr) return cdr::transform(p, n);
	checkMd5<geometry_msgs::Transform>(c.md5);
	// translation (Vector3), rotation (Quaternion): seven float64
	if (n < 56)
		throw runtime_error(mrpt::format(
		    "%zu bytes: shorter than a geometry_msgs/Transform (56)", n));
	TransformView v;
	std::memcpy(v.t, p, 24);
	std::memcpy(v.q, p + 24, 32);
	return v;
}

}  // namespace bims::bag
