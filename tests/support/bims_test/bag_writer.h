// Writing ROS 1 bags from rawlog observations with the rosbag API, as a
// realsense-ros or TUM RGB-D recording holds them (the tests and the bench
// of bims-import-bag): depth (16UC1 mm or 32FC1 m), colour, CameraInfo,
// sensor_msgs/Imu as one topic, as separate accelerometer and gyro topics
// at different rates, or accelerometer only, MagneticField.
#pragma once

#include <bims/bag/bag_import.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/MagneticField.h>

#include <cmath>
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
		bag.write(layout.depth, t, depthMsg(f, spec.tum));
		bag.write(layout.colour, t, colourMsg(f, spec.colour));
	}
	bag.close();
}

}  // namespace bims::test
