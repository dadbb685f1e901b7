// [ros2]: the topics, QoS and frames of bims-ros2, the live node
// (docs/ros2.md). The defaults are realsense-ros 4.x's topics with the
// depth aligned to colour and the IMU united into one topic.
#pragma once

#include <bims/common/options.h>
#include <mrpt/config/CConfigFileBase.h>

#include <string>

namespace bims::ros2
{
struct Ros2Params
{
	std::string depthTopic = "/camera/camera/aligned_depth_to_color/image_raw";
	std::string colourTopic = "/camera/camera/color/image_raw";
	std::string cameraInfoTopic = "/camera/camera/color/camera_info";
	std::string imuTopic = "/camera/camera/imu";
	std::string magTopic = "none";
	std::string maskTopic = "/bims/moving_mask";
	std::string odometryTopic = "/bims/odometry";
	std::string pointsTopic = "/bims/moving_points";
	/** frame_id of the odometry and the moving points (the world). */
	std::string worldFrame = "bims_world";
	/** metres per unit of a 16UC1 depth image (REP 118: mm). */
	double depthUnits = 0.001;
	/** metres per unit of the scans' range image. */
	double rangeUnits = 0.001;
	/** max |t_colour - t_depth| to pair a colour image with a depth one. */
	double maxTimeGap = 0.02;
	/** wall time a depth image waits for its colour image before it runs
	 * without it [s]. */
	double colourWait = 0.5;
	/** frames waiting to be processed; one more drops the oldest. */
	int queueFrames = 2;
	/** QoS history depth (keep last) of every reader and writer. */
	int historyDepth = 5;
	/** DDS domain (ROS_DOMAIN_ID). */
	int domainId = 0;

	void describe(OptionVisitor& v);
	/** Reads [ros2] strictly (unknown keys, values out of range: errors
	 * naming the file, section and key). */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg);
};

/** "none" or empty: the topic is not read. */
bool topicGiven(const std::string& topic);

}  // namespace bims::ros2
