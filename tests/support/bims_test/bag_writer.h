// Writing ROS 1 bags from rawlog observations with the rosbag API, as a
// realsense-ros or TUM RGB-D recording holds them (the tests and the bench
// of bims-import-bag): depth (16UC1 mm or 32FC1 m), colour, CameraInfo,
// sensor_msgs/Imu as one topic, as separate accelerometer and gyro topics
// at different rates, or accelerometer only, MagneticField; the images
// also as image_transport's plugins republish them (sensor_msgs/
// CompressedImage: compressed colour, compressedDepth depth).
#pragma once

#include <bims/bag/bag_import.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>

#include <algorithm>
#include <cmath>
#include <cstring>
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

/** The depth as compressed_depth_image_transport writes it (format
 * "16UC1; compressedDepth png" or "32FC1; ..."): its 12-byte ConfigHeader
 * (format INV_DEPTH = 0, depthQuantA, depthQuantB), then a PNG of the
 * 16UC1 millimetres as they are, or of the 32FC1 metres' inverse quantised
 * as the plugin does it with its defaults (depth_quantization 100,
 * depth_max 10 m: v = A / d + B truncated, 0 beyond depth_max and for no
 * reading, 0 or NaN; the plugin's float-to-uint16 conversion of A / 0 is
 * undefined, 0 on x86). (The plugin also zeroes 16UC1 readings beyond
 * depth_max; the sample has none.) */
inline sensor_msgs::CompressedImage compressedDepthMsg(
    const CObservation3DRangeScan& f, bool metres)
{
	const sensor_msgs::Image raw = depthMsg(f, metres);
	sensor_msgs::CompressedImage m;
	m.header = raw.header;
	m.format = raw.encoding + "; compressedDepth png";
	const int W = static_cast<int>(raw.width), H = static_cast<int>(raw.height);
	float quant[2] = {0, 0};
	cv::Mat png(H, W, CV_16UC1);
	if (metres)
	{
		const float z0 = 100, depthMax = 10;
		quant[0] = z0 * (z0 + 1.0f);
		quant[1] = 1.0f - quant[0] / depthMax;
		const auto* d = reinterpret_cast<const float*>(raw.data.data());
		for (int v = 0; v < H; v++)
			for (int u = 0; u < W; u++)
			{
				const float z = d[v * W + u];
				png.at<uint16_t>(v, u) =
				    z > 0 && z < depthMax
				        ? static_cast<uint16_t>(
				              std::min(65535.0f, quant[0] / z + quant[1]))
				        : 0;
			}
	}
	else
		std::memcpy(png.data, raw.data.data(), raw.data.size());
	m.data.resize(12);
	const int32_t invDepth = 0;
	std::memcpy(m.data.data(), &invDepth, 4);
	std::memcpy(m.data.data() + 4, quant, 8);
	std::vector<uint8_t> bytes;
	cv::imencode(".png", png, bytes, {cv::IMWRITE_PNG_COMPRESSION, 1});
	m.data.insert(m.data.end(), bytes.begin(), bytes.end());
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
	/** The depth as compressed_depth_image_transport's, on the layout's
	 * depth topic + "/compressedDepth", instead of the raw topic. */
	bool compressedDepth = false;
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
			          compressedDepthMsg(f, spec.tum));
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

}  // namespace bims::test
