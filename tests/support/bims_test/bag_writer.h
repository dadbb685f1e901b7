// Writing ROS 1 bags from rawlog observations with the rosbag API, as a
// realsense-ros or TUM RGB-D recording holds them (the tests and the bench
// of bims-import-bag): depth (16UC1 mm or 32FC1 m), colour, CameraInfo,
// sensor_msgs/Imu as one topic, as separate accelerometer and gyro topics
// at different rates, or accelerometer only, MagneticField; the images
// also as image_transport's plugins republish them (sensor_msgs/
// CompressedImage: compressed colour, compressedDepth depth as PNG or RVL).
#pragma once

#include <bims/bag/bag_import.h>
#include <geometry_msgs/Transform.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>
#include <std_msgs/Float32.h>
#include <std_msgs/String.h>
#include <std_msgs/UInt32.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace bims::test
{
using mrpt::obs::CObservation3DRangeScan;
using mrpt::obs::CObservationIMU;

inline double secondsOf(const mrpt::Clock::time_point& t)
{
	return mrpt::Clock::toDouble(t);
}

/** A stamp rounded to the microsecond (what a TUM list file can hold). */
inline ros::Time rosTime(double t)
{
	const double us = std::round(t * 1e6);
	const auto sec = static_cast<uint32_t>(std::floor(us / 1e6));
	const auto usec = static_cast<uint32_t>(us - double(sec) * 1e6);
	return ros::Time(sec, usec * 1000);
}

inline std_msgs::Header header(double t, const char* frame)
{
	std_msgs::Header h;
	h.stamp = rosTime(t);
	h.frame_id = frame;
	return h;
}

/** A depth reading as a TUM PNG holds it: 5000 per metre (0: none or
 * beyond the PNG's range). */
inline uint16_t tumUnits(const CObservation3DRangeScan& f, int v, int u)
{
	const double units = std::round(f.rangeImage(v, u) * 5.0);  // mm * 5
	return units <= 65535 ? static_cast<uint16_t>(units) : 0;
}

inline sensor_msgs::Image depthMsg(const CObservation3DRangeScan& f,
                                   bool metres)
{
	sensor_msgs::Image m;
	m.header = header(secondsOf(f.timestamp), "depth");
	m.height = f.rangeImage.rows();
	m.width = f.rangeImage.cols();
	if (metres)
	{
		// as a TUM PNG would hold it (5000 per metre), then in metres
		m.encoding = "32FC1";
		m.step = m.width * 4;
		m.data.resize(m.step * m.height);
		auto* p = reinterpret_cast<float*>(m.data.data());
		for (uint32_t v = 0; v < m.height; v++)
			for (uint32_t u = 0; u < m.width; u++)
				p[v * m.width + u] =
				    static_cast<float>(tumUnits(f, v, u) / 5000.0);
	}
	else
	{
		m.encoding = "16UC1";
		m.step = m.width * 2;
		m.data.resize(m.step * m.height);
		auto* p = reinterpret_cast<uint16_t*>(m.data.data());
		for (uint32_t v = 0; v < m.height; v++)
			for (uint32_t u = 0; u < m.width; u++)
				p[v * m.width + u] = f.rangeImage(v, u);  // mm
	}
	return m;
}

inline cv::Mat bgrOf(const CObservation3DRangeScan& f)
{
	return f.intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY);
}

inline sensor_msgs::Image colourMsg(const CObservation3DRangeScan& f,
                                    const std::string& encoding)
{
	cv::Mat img = bgrOf(f).clone();  // the sample's own stays as it is
	if (encoding == "rgb8") cv::cvtColor(img, img, cv::COLOR_BGR2RGB);
	sensor_msgs::Image m;
	m.header = header(secondsOf(f.timestamp), "colour");
	m.height = img.rows;
	m.width = img.cols;
	m.encoding = encoding;
	m.step = img.cols * 3;
	m.data.assign(img.data, img.data + img.total() * 3);
	return m;
}

/** The colour as compressed_image_transport writes it: \a codec "jpeg"
 * (quality \a jpegQuality) or "png" of the BGR pixels, the format
 * "rgb8; CODEC compressed bgr8" (or \a format when given). */
inline sensor_msgs::CompressedImage compressedColourMsg(
    const CObservation3DRangeScan& f, const std::string& codec,
    const std::string& format = "", int jpegQuality = 90)
{
	sensor_msgs::CompressedImage m;
	m.header = header(secondsOf(f.timestamp), "colour");
	m.format = format.empty() ? "rgb8; " + codec + " compressed bgr8" : format;
	const bool jpeg = codec == "jpeg";
	const std::vector<int> params = {
	    jpeg ? cv::IMWRITE_JPEG_QUALITY : cv::IMWRITE_PNG_COMPRESSION,
	    jpeg ? jpegQuality : 1};
	cv::imencode(jpeg ? ".jpg" : ".png", bgrOf(f), m.data, params);
	return m;
}

/** Andrew D. Wilson's RVL ("Fast Lossless Depth Image Compression", ISS
 * 2017) as compressed_depth_image_transport writes it: the tests' own
 * encoder, written from the algorithm, for the importer's decoder to be
 * checked against. Numbers are written 3 bits a nibble, the lowest first,
 * the nibble's high bit set when more follow; the nibbles fill 32-bit words
 * (in this machine's byte order, as the plugin's) from the high end, the
 * last word padded with zero nibbles. */
class RvlWriter
{
 public:
	void number(uint32_t v)
	{
		do
		{
			const uint32_t low = v & 7;
			v >>= 3;
			nibble(v ? low | 8 : low);
		} while (v);
	}

	std::vector<uint8_t> finish()
	{
		if (nibbles_ > 0)
		{
			word_ <<= 4 * (8 - nibbles_);
			flush();
		}
		return std::move(bytes_);
	}

 private:
	void nibble(uint32_t x)
	{
		word_ = word_ << 4 | x;
		if (++nibbles_ == 8) flush();
	}

	void flush()
	{
		const size_t at = bytes_.size();
		bytes_.resize(at + 4);
		std::memcpy(&bytes_[at], &word_, 4);
		word_ = 0;
		nibbles_ = 0;
	}

	std::vector<uint8_t> bytes_;
	uint32_t word_ = 0;
	int nibbles_ = 0;
};

/** The RVL stream of the \a n pixels at \a px: pairs of runs, the count of
 * zeros then of readings (non-zero), each reading as its difference d from
 * the reading before (across runs and rows; the first from 0), zig-zagged
 * to a natural number: 2d, or -2d - 1 below 0. */
inline std::vector<uint8_t> rvlEncoded(const uint16_t* px, size_t n)
{
	RvlWriter w;
	int previous = 0;
	for (size_t i = 0; i < n;)
	{
		const size_t zeros =
		    std::find_if(px + i, px + n, [](uint16_t v) { return v != 0; }) -
		    (px + i);
		const size_t readings =
		    std::find(px + i + zeros, px + n, uint16_t{0}) - (px + i + zeros);
		w.number(static_cast<uint32_t>(zeros));
		w.number(static_cast<uint32_t>(readings));
		i += zeros;
		for (size_t k = 0; k < readings; k++, i++)
		{
			const int d = px[i] - previous;
			w.number(static_cast<uint32_t>(d >= 0 ? 2 * d : -2 * d - 1));
			previous = px[i];
		}
	}
	return w.finish();
}

/** The 32FC1 metres \a z as compressed_depth_image_transport quantises
 * them, with its defaults (depth_quantization 100, depth_max 10 m): v = A /
 * z + B truncated, 0 beyond depth_max and for no reading, 0 or NaN (the
 * plugin's float-to-uint16 conversion of A / 0 is undefined, 0 on x86);
 * \a quant: A and B, for the ConfigHeader. */
inline cv::Mat quantisedInverseDepth(const cv::Mat& z, float quant[2])
{
	const float z0 = 100, depthMax = 10;
	quant[0] = z0 * (z0 + 1.0f);
	quant[1] = 1.0f - quant[0] / depthMax;
	cv::Mat v(z.size(), CV_16UC1);
	for (int r = 0; r < z.rows; r++)
		for (int c = 0; c < z.cols; c++)
		{
			const float d = z.at<float>(r, c);
			v.at<uint16_t>(r, c) = d > 0 && d < depthMax
			                           ? static_cast<uint16_t>(std::min(
			                                 65535.0f, quant[0] / d + quant[1]))
			                           : 0;
		}
	return v;
}

/** compressed_depth_image_transport's data for the 16-bit image \a v (the
 * millimetres, or the quantised inverse depth of \a quant): its 12-byte
 * ConfigHeader (format INV_DEPTH = 0, depthQuantA, depthQuantB), then a PNG
 * of \a v, or (\a codec "rvl") v's cols and rows as uint32 and its RVL
 * stream. */
inline std::vector<uint8_t> compressedDepthData(const cv::Mat& v,
                                                const std::string& codec,
                                                const float quant[2])
{
	std::vector<uint8_t> data(12), bytes;
	const int32_t invDepth = 0;
	std::memcpy(data.data(), &invDepth, 4);
	std::memcpy(data.data() + 4, quant, 8);
	if (codec == "rvl")
	{
		const cv::Mat c = v.clone();  // continuous
		const uint32_t size[2] = {static_cast<uint32_t>(c.cols),
		                          static_cast<uint32_t>(c.rows)};
		bytes.resize(8);
		std::memcpy(bytes.data(), size, 8);
		const auto rvl = rvlEncoded(c.ptr<uint16_t>(), c.total());
		bytes.insert(bytes.end(), rvl.begin(), rvl.end());
	}
	else
		cv::imencode(".png", v, bytes, {cv::IMWRITE_PNG_COMPRESSION, 1});
	data.insert(data.end(), bytes.begin(), bytes.end());
	return data;
}

/** The depth as compressed_depth_image_transport writes it (format
 * "16UC1; compressedDepth CODEC" or "32FC1; ...", \a codec "png" or
 * "rvl"): the 16UC1 millimetres as they are, or the 32FC1 metres' inverse
 * quantised as the plugin does it with its defaults. (The plugin also zeroes
 * 16UC1 readings beyond depth_max; the sample has none.) */
inline sensor_msgs::CompressedImage compressedDepthMsg(
    const CObservation3DRangeScan& f, bool metres,
    const std::string& codec = "png")
{
	sensor_msgs::Image raw = depthMsg(f, metres);
	sensor_msgs::CompressedImage m;
	m.header = raw.header;
	m.format = raw.encoding + "; compressedDepth " + codec;
	const cv::Mat plane(static_cast<int>(raw.height),
	                    static_cast<int>(raw.width),
	                    metres ? CV_32FC1 : CV_16UC1, raw.data.data());
	float quant[2] = {0, 0};
	m.data = compressedDepthData(
	    metres ? quantisedInverseDepth(plane, quant) : plane, codec, quant);
	return m;
}

inline sensor_msgs::CameraInfo infoMsg(const CObservation3DRangeScan& f)
{
	sensor_msgs::CameraInfo m;
	m.header = header(secondsOf(f.timestamp), "colour");
	m.width = f.cameraParams.ncols;
	m.height = f.cameraParams.nrows;
	m.distortion_model = "plumb_bob";
	m.D.assign(5, 0.0);
	m.K = {f.cameraParams.fx(),
	       0,
	       f.cameraParams.cx(),
	       0,
	       f.cameraParams.fy(),
	       f.cameraParams.cy(),
	       0,
	       0,
	       1};
	return m;
}

inline sensor_msgs::Imu imuMsg(const CObservationIMU& o, bool gyro, bool accel)
{
	using namespace mrpt::obs;
	sensor_msgs::Imu m;
	m.header = header(secondsOf(o.timestamp), "imu");
	m.orientation_covariance[0] = -1;
	if (gyro)
	{
		m.angular_velocity.x = o.get(IMU_WX);
		m.angular_velocity.y = o.get(IMU_WY);
		m.angular_velocity.z = o.get(IMU_WZ);
	}
	else
		m.angular_velocity_covariance[0] = -1;
	if (accel)
	{
		m.linear_acceleration.x = o.get(IMU_X_ACC);
		m.linear_acceleration.y = o.get(IMU_Y_ACC);
		m.linear_acceleration.z = o.get(IMU_Z_ACC);
	}
	else
		m.linear_acceleration_covariance[0] = -1;
	return m;
}

inline sensor_msgs::MagneticField magMsg(const CObservationIMU& o)
{
	using namespace mrpt::obs;
	sensor_msgs::MagneticField m;
	m.header = header(secondsOf(o.timestamp), "imu");
	m.magnetic_field.x = o.get(IMU_MAG_X) * 1e-4;  // gauss to tesla
	m.magnetic_field.y = o.get(IMU_MAG_Y) * 1e-4;
	m.magnetic_field.z = o.get(IMU_MAG_Z) * 1e-4;
	return m;
}

struct BagSpec
{
	bool tum = false;       ///< TUM RGB-D's topics, 32FC1, accel-only
	bool splitImu = false;  ///< RealSense's accel + gyro topics
	bool mag = false;       ///< a /imu/mag MagneticField topic
	std::string colour = "rgb8";
	/** "jpeg" or "png": the colour as a CompressedImage on the layout's
	 * colour topic + "/compressed" (format colourFormat, when given),
	 * instead of the raw topic. */
	std::string colourCodec;
	std::string colourFormat;
	/** The depth as compressed_depth_image_transport's (its codec
	 * depthCodec: "png" or "rvl"), on the layout's depth topic +
	 * "/compressedDepth", instead of the raw topic. */
	bool compressedDepth = false;
	std::string depthCodec = "png";
	rosbag::compression::CompressionType compression =
	    rosbag::compression::Uncompressed;
	size_t frames = 24;  ///< the first N frames
};

/** Writes the first spec.frames of \a frames and the IMU samples up to
 * the last as a bag of \a spec's layout, each message at its header
 * stamp. */
inline void writeBag(const std::string& path, const BagSpec& spec,
                     const std::vector<CObservation3DRangeScan::Ptr>& frames,
                     const std::vector<CObservationIMU::Ptr>& imu)
{
	rosbag::Bag bag(path, rosbag::bagmode::Write);
	bag.setCompression(spec.compression);
	bag.setChunkThreshold(256 * 1024);  // several chunks
	const auto layout = bag::layoutTopics(spec.tum ? bag::BagLayout::Tum
	                                               : bag::BagLayout::RealSense);
	size_t i = 0, n = 0;
	for (size_t k = 0; k < spec.frames; k++)
	{
		const auto& f = *frames[k];
		const double tf = secondsOf(f.timestamp);
		for (; i < imu.size() && secondsOf(imu[i]->timestamp) <= tf; i++)
		{
			const auto& o = *imu[i];
			const ros::Time t = rosTime(secondsOf(o.timestamp));
			if (spec.tum)
				bag.write(layout.imu, t, imuMsg(o, false, true));
			else if (spec.splitImu)
			{
				bag.write(layout.gyro, t, imuMsg(o, true, false));
				if (n++ % 2 == 0)  // the accelerometer at half the rate
					bag.write(layout.accel, t, imuMsg(o, false, true));
			}
			else
				bag.write(layout.imu, t, imuMsg(o, true, true));
			if (spec.mag) bag.write("/imu/mag", t, magMsg(o));
		}
		const ros::Time t = rosTime(tf);
		bag.write(layout.cameraInfo, t, infoMsg(f));
		if (spec.compressedDepth)
			bag.write(layout.depth + "/compressedDepth", t,
			          compressedDepthMsg(f, spec.tum, spec.depthCodec));
		else
			bag.write(layout.depth, t, depthMsg(f, spec.tum));
		if (!spec.colourCodec.empty())
			bag.write(
			    layout.colour + "/compressed", t,
			    compressedColourMsg(f, spec.colourCodec, spec.colourFormat));
		else
			bag.write(layout.colour, t, colourMsg(f, spec.colour));
	}
	bag.close();
}

// ---------------------------------------------------------------------
// The RealSense SDK's own recordings (librealsense's "ROS file format", as
// RealSense Viewer and rs-record write them), written here from its
// documented layout (librealsense's src/media/ros/ros_file_format.h and
// ros_writer.cpp), independently of bims's reader: /file_version, per
// stream /device_0/sensor_S/<Stream>_0/{image|imu}/data, its
// info/camera_info, its tf/0 (geometry_msgs/Transform from the reference
// stream, the depth, to the stream: p_stream = R p_ref + t), the depth
// sensor's option/Depth Units/value (std_msgs/Float32). Motion samples are
// sensor_msgs/Imu with one field filled and every covariance 0, accel and
// gyro on streams of their own at different rates; stamps the device's,
// record times from the recording's start.
// ---------------------------------------------------------------------

/** A sensor_msgs/Image as librealsense's recorder serializes a depth frame
 * since it keeps the depth units with it: the message, then a float32 (the
 * same type and MD5 sum). */
struct RsSdkImage
{
	sensor_msgs::Image image;
	float depthUnits = 0;
};
}  // namespace bims::test

namespace ros::message_traits
{
template <>
struct MD5Sum<bims::test::RsSdkImage>
{
	static const char* value() { return MD5Sum<sensor_msgs::Image>::value(); }
	static const char* value(const bims::test::RsSdkImage&) { return value(); }
};
template <>
struct DataType<bims::test::RsSdkImage>
{
	static const char* value() { return DataType<sensor_msgs::Image>::value(); }
	static const char* value(const bims::test::RsSdkImage&) { return value(); }
};
template <>
struct Definition<bims::test::RsSdkImage>
{
	static const char* value()
	{
		return Definition<sensor_msgs::Image>::value();
	}
	static const char* value(const bims::test::RsSdkImage&) { return value(); }
};
}  // namespace ros::message_traits

namespace ros::serialization
{
template <>
struct Serializer<bims::test::RsSdkImage>
{
	template <typename Stream>
	inline static void write(Stream& s, const bims::test::RsSdkImage& m)
	{
		s.next(m.image);
		s.next(m.depthUnits);
	}
	template <typename Stream>
	inline static void read(Stream& s, bims::test::RsSdkImage& m)
	{
		s.next(m.image);
		s.next(m.depthUnits);
	}
	inline static uint32_t serializedLength(const bims::test::RsSdkImage& m)
	{
		return serializationLength(m.image) + 4;
	}
};
}  // namespace ros::serialization

namespace bims::test
{
/** What an SDK recording of the sample holds. */
struct RsSdkSpec
{
	size_t frames = 24;
	/** The sensors' numbers (a D435i's: stereo module 0, RGB camera 1,
	 * motion module 2; other models differ). */
	int depthSensor = 0, colourSensor = 1, motionSensor = 2;
	/** The option's name in its topic ("Depth Units", newer librealsense
	 * "Depth_Units"); empty: no option. */
	std::string unitsOption = "Depth Units";
	float units = 0.001f;  ///< metres per unit of the depth images
	/** The depth units after each depth image's data, as the newer
	 * recorder appends them (0: none). */
	float imageUnits = 0;
	std::string depthEncoding = "mono16";  ///< or 16UC1; 32FC1: metres
	bool colour = true, depthInfo = true, colourInfo = true;
	bool accel = true, gyro = true, tf = true;
	/** The colour camera: the depth's scaled by this (its images the
	 * sample's resized). */
	int colourScale = 1;
	/** From the depth (the reference stream) to the colour and to the
	 * motion module's accel and gyro. */
	bag::RigidTransform colourTf, imuTf;
	bool nanColourTf = false;  ///< the colour's tf all NaN
};

inline geometry_msgs::Transform tfMsg(const bag::RigidTransform& T)
{
	Eigen::Matrix3d R;
	for (int i = 0; i < 9; i++) R(i / 3, i % 3) = T.R[i];
	const Eigen::Quaterniond q(R);
	geometry_msgs::Transform m;
	m.translation.x = T.t[0];
	m.translation.y = T.t[1];
	m.translation.z = T.t[2];
	m.rotation.x = q.x();
	m.rotation.y = q.y();
	m.rotation.z = q.z();
	m.rotation.w = q.w();
	return m;
}

/** The sample's camera scaled by \a s (pixel centres kept in place). */
inline sensor_msgs::CameraInfo scaledInfoMsg(const CObservation3DRangeScan& f,
                                             int s)
{
	sensor_msgs::CameraInfo m = infoMsg(f);
	m.width *= s;
	m.height *= s;
	m.K[0] *= s;
	m.K[4] *= s;
	m.K[2] = (m.K[2] + 0.5) * s - 0.5;
	m.K[5] = (m.K[5] + 0.5) * s - 0.5;
	// librealsense writes its distortion model's name and 5 coefficients
	m.distortion_model = "Brown Conrady";
	return m;
}

/** The SDK's motion sample: one vector filled, every covariance 0. */
inline sensor_msgs::Imu sdkImuMsg(const CObservationIMU& o, bool gyro)
{
	using namespace mrpt::obs;
	sensor_msgs::Imu m;
	m.header = header(secondsOf(o.timestamp), "");
	if (gyro)
	{
		m.angular_velocity.x = o.get(IMU_WX);
		m.angular_velocity.y = o.get(IMU_WY);
		m.angular_velocity.z = o.get(IMU_WZ);
	}
	else
	{
		m.linear_acceleration.x = o.get(IMU_X_ACC);
		m.linear_acceleration.y = o.get(IMU_Y_ACC);
		m.linear_acceleration.z = o.get(IMU_Z_ACC);
	}
	return m;
}

/** Writes the first spec.frames of \a frames and the IMU samples up to the
 * last as a RealSense SDK recording. */
inline void writeRsSdkBag(
    const std::string& path, const RsSdkSpec& spec,
    const std::vector<CObservation3DRangeScan::Ptr>& frames,
    const std::vector<CObservationIMU::Ptr>& imu)
{
	rosbag::Bag bag(path, rosbag::bagmode::Write);
	bag.setChunkThreshold(256 * 1024);
	const double t0 = secondsOf(frames.front()->timestamp) - 0.5;
	// record times from the recording's start, as the SDK's
	auto rec = [&](double t) { return ros::Time(1.0 + t - t0); };
	const std::string dev = "/device_0/";
	auto sensor = [&](int s) { return dev + "sensor_" + std::to_string(s); };
	const std::string depth = sensor(spec.depthSensor) + "/Depth_0",
	                  colour = sensor(spec.colourSensor) + "/Color_0",
	                  accel = sensor(spec.motionSensor) + "/Accel_0",
	                  gyro = sensor(spec.motionSensor) + "/Gyro_0";
	const ros::Time start = rec(t0);
	std_msgs::UInt32 version;
	version.data = 4;
	bag.write("/file_version", start, version);
	const auto& f0 = *frames.front();
	if (!spec.unitsOption.empty())
	{
		const std::string opt =
		    sensor(spec.depthSensor) + "/option/" + spec.unitsOption;
		std_msgs::Float32 u;
		u.data = spec.units;
		bag.write(opt + "/value", start, u);
		std_msgs::String d;
		d.data = "Number of meters represented by a single depth unit";
		bag.write(opt + "/description", start, d);
	}
	if (spec.depthInfo)
		bag.write(depth + "/info/camera_info", start, scaledInfoMsg(f0, 1));
	if (spec.colour && spec.colourInfo)
		bag.write(colour + "/info/camera_info", start,
		          scaledInfoMsg(f0, spec.colourScale));
	size_t i = 0, n = 0;
	bool tfWritten = false;
	for (size_t k = 0; k < spec.frames; k++)
	{
		const auto& f = *frames[k];
		const double tf = secondsOf(f.timestamp);
		for (; i < imu.size() && secondsOf(imu[i]->timestamp) <= tf; i++)
		{
			const auto& o = *imu[i];
			const ros::Time t = rec(secondsOf(o.timestamp));
			if (spec.gyro) bag.write(gyro + "/imu/data", t, sdkImuMsg(o, true));
			if (spec.accel && n++ % 2 == 0)  // at half the gyro's rate
				bag.write(accel + "/imu/data", t, sdkImuMsg(o, false));
		}
		const ros::Time t = rec(tf);
		RsSdkImage d;
		d.image = depthMsg(f, spec.depthEncoding == "32FC1");
		d.image.header.frame_id.clear();
		if (spec.depthEncoding != "32FC1")
		{
			d.image.encoding = spec.depthEncoding;
			auto* p = reinterpret_cast<uint16_t*>(d.image.data.data());
			for (size_t j = 0; j < d.image.data.size() / 2; j++)
				p[j] = static_cast<uint16_t>(
				    std::lround(p[j] * (0.001 / spec.units)));
		}
		d.depthUnits = spec.imageUnits;
		if (spec.imageUnits != 0)
			bag.write(depth + "/image/data", t, d);
		else
			bag.write(depth + "/image/data", t, d.image);
		if (spec.colour)
		{
			auto c = colourMsg(f, "rgb8");
			if (spec.colourScale != 1)
			{
				cv::Mat img(c.height, c.width, CV_8UC3, c.data.data());
				cv::Mat big;
				cv::resize(img, big, cv::Size(), spec.colourScale,
				           spec.colourScale, cv::INTER_NEAREST);
				c.width = big.cols;
				c.height = big.rows;
				c.step = big.cols * 3;
				c.data.assign(big.data, big.data + big.total() * 3);
			}
			bag.write(colour + "/image/data", t, c);
		}
		if (!tfWritten && spec.tf)
		{
			// written with each stream's first frame, as the recorder does
			tfWritten = true;
			bag.write(depth + "/tf/0", t, tfMsg(bag::RigidTransform()));
			if (spec.colour)
			{
				auto m = tfMsg(spec.colourTf);
				if (spec.nanColourTf)
					m.translation.x = m.rotation.w =
					    std::numeric_limits<double>::quiet_NaN();
				bag.write(colour + "/tf/0", t, m);
			}
			if (spec.accel) bag.write(accel + "/tf/0", t, tfMsg(spec.imuTf));
			if (spec.gyro) bag.write(gyro + "/tf/0", t, tfMsg(spec.imuTf));
		}
	}
	bag.close();
}

}  // namespace bims::test
