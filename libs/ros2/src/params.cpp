#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/ros2/params.h>

namespace bims::ros2
{
void Ros2Params::describe(OptionVisitor& v)
{
	v.text("depth_topic", depthTopic,
	       "sensor_msgs/Image, 16UC1 (depth_units) or 32FC1 (m)");
	v.text("colour_topic", colourTopic,
	       "sensor_msgs/Image rgb8/bgr8/mono8 registered to the depth; none: "
	       "depth only");
	v.text("camera_info_topic", cameraInfoTopic,
	       "sensor_msgs/CameraInfo of the depth image (its K, D and size)");
	v.text("imu_topic", imuTopic, "sensor_msgs/Imu; none: no IMU");
	v.text("mag_topic", magTopic,
	       "sensor_msgs/MagneticField attached to the IMU sample of its "
	       "stamp; none: no magnetometer");
	v.text("mask_topic", maskTopic,
	       "published: sensor_msgs/Image mono8, 255 = moving");
	v.text("odometry_topic", odometryTopic,
	       "published: nav_msgs/Odometry, the camera's pose T_WC");
	v.text("points_topic", pointsTopic,
	       "published: sensor_msgs/PointCloud2, the moving voxels' centres");
	v.text("world_frame", worldFrame,
	       "frame_id of the odometry and the moving points");
	v.real("depth_units", depthUnits, 1e-6, 0.1,
	       "metres per unit of a 16UC1 depth image");
	v.real("range_units", rangeUnits, 1e-6, 0.1,
	       "metres per unit of the scans' range image");
	v.real("max_time_gap_s", maxTimeGap, 0, 1,
	       "max |t_colour - t_depth| to pair [s]");
	v.real("colour_wait_s", colourWait, 0, 10,
	       "wall time a depth image waits for its colour [s]");
	v.integer("queue_frames", queueFrames, 1, 1000,
	          "frames waiting to be processed; one more drops the oldest");
	v.integer("history_depth", historyDepth, 1, 1000,
	          "QoS keep-last depth of every reader and writer");
	v.integer("domain_id", domainId, 0, 232, "DDS domain (ROS_DOMAIN_ID)");
}

void Ros2Params::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg)
{
	checkExperimentSections(cfg);
	readOptions(*this, cfg, "ros2");
	ConfigSection s(cfg, "ros2");
	for (const auto& [key, topic] :
	     {std::pair<const char*, std::string*>{"depth_topic", &depthTopic},
	      {"mask_topic", &maskTopic},
	      {"odometry_topic", &odometryTopic},
	      {"points_topic", &pointsTopic}})
		if (!topicGiven(*topic) || topic->front() != '/')
			s.fail(key, "'" + *topic + "': a topic name starting with /");
}

bool topicGiven(const std::string& topic)
{
	return !topic.empty() && topic != "none";
}

}  // namespace bims::ros2
