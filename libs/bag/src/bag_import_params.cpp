#include <bims/bag/bag_import.h>
#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/eval/rgbd_frame.h>
#include <bims/sensors/params.h>

namespace bims::bag
{
BagTopics layoutTopics(BagLayout layout)
{
	BagTopics t;
	switch (layout)
	{
		case BagLayout::RealSense:
			// realsense-ros (ROS 1) with align_depth:=true; its IMU comes
			// as one topic (unite_imu_method) or as two at their own rates
			t.depth = "/camera/aligned_depth_to_color/image_raw";
			t.colour = "/camera/color/image_raw";
			t.cameraInfo = "/camera/color/camera_info";
			t.imu = "/camera/imu";
			t.accel = "/camera/accel/sample";
			t.gyro = "/camera/gyro/sample";
			break;
		case BagLayout::Tum:
			// the TUM RGB-D benchmark's bags: depth registered to colour,
			// in metres; the Kinect's accelerometer
			t.depth = "/camera/depth/image";
			t.colour = "/camera/rgb/image_color";
			t.cameraInfo = "/camera/rgb/camera_info";
			t.imu = "/imu";
			break;
		case BagLayout::Auto:
		case BagLayout::RsSdk:  // found by name: rsSdkTopics()
			break;
	}
	return t;
}

std::vector<BagTopics> layoutVariants(BagLayout layout)
{
	std::vector<BagTopics> v = {layoutTopics(layout)};
	if (layout != BagLayout::RealSense) return v;
	// realsense-ros 4.x (ROS 2): its node in namespace "camera" named
	// "camera"; with align_depth.enable:=true the aligned depth, else the
	// depth alone (in the depth camera's frame: no colour attached)
	BagTopics t;
	t.depth = "/camera/camera/aligned_depth_to_color/image_raw";
	t.colour = "/camera/camera/color/image_raw";
	t.cameraInfo = "/camera/camera/color/camera_info";
	t.imu = "/camera/camera/imu";
	t.accel = "/camera/camera/accel/sample";
	t.gyro = "/camera/camera/gyro/sample";
	v.push_back(t);
	t.depth = "/camera/camera/depth/image_rect_raw";
	t.colour.clear();
	t.cameraInfo = "/camera/camera/depth/camera_info";
	v.push_back(t);
	return v;
}

BagTopics resolveTopics(const BagTopics& given, BagLayout layout)
{
	return resolveTopics(given, layoutTopics(layout));
}

BagTopics resolveTopics(const BagTopics& given, const BagTopics& preset)
{
	BagTopics t = preset;
	auto pick = [](std::string& preset, const std::string& g)
	{
		if (g == "none")
			preset.clear();
		else if (!g.empty())
			preset = g;
	};
	pick(t.depth, given.depth);
	pick(t.colour, given.colour);
	pick(t.cameraInfo, given.cameraInfo);
	pick(t.imu, given.imu);
	pick(t.accel, given.accel);
	pick(t.gyro, given.gyro);
	pick(t.mag, given.mag);
	return t;
}

void BagImportParams::describe(OptionVisitor& v)
{
	v.choice("layout", layout,
	         "whose preset topics: realsense (realsense-ros, aligned "
	         "depth), tum (TUM RGB-D's bags), rs-sdk (the RealSense SDK's "
	         "own recordings: RealSense Viewer, rs-record), auto (the first "
	         "whose depth topic the bag has); --layout overrides");
	// each topic key: empty takes the layout's topic, "none" reads none
	v.text("depth_topic", topics.depth,
	       "depth image topic, 16UC1 mm or 32FC1 m, raw or compressedDepth "
	       "(empty: the layout's; none: not read)");
	v.text("colour_topic", topics.colour,
	       "colour image topic, rgb8 bgr8 mono8, raw or compressed (empty: "
	       "the layout's)");
	v.text("camera_info_topic", topics.cameraInfo,
	       "CameraInfo topic of the registered depth image (empty: the "
	       "layout's)");
	v.text("imu_topic", topics.imu,
	       "sensor_msgs/Imu topic (empty: the layout's; none: not read)");
	v.text("accel_topic", topics.accel,
	       "accelerometer-only Imu topic, merged with gyro_topic (empty: "
	       "the layout's)");
	v.text("gyro_topic", topics.gyro,
	       "gyro-only Imu topic; the merged IMU has its rate (empty: the "
	       "layout's)");
	v.text("mag_topic", topics.mag,
	       "sensor_msgs/MagneticField topic (empty: the layout's)");
	v.real("max_time_gap_s", maxTimeGap, 0.0, 10.0,
	       "max |t_colour - t_depth| to pair a depth and a colour image [s]");
	v.choice("timestamp", timestampFrom,
	         "which image's stamp a frame takes (the geometry's: depth)");
	v.real("depth_units", depthUnits, 0.0, 0.1,
	       "rs-sdk: metres per unit of the recording's 16-bit depth (0: its "
	       "Depth Units option, else its images' own); given, it replaces "
	       "the recording's; --depth-units overrides");
	v.real("range_units", rangeUnits, 1e-6, 0.1,
	       "metres per unit of the rawlog's uint16 range image");
	v.text("accel_label", accelLabel,
	       "sensor label of IMU samples without a gyro (an accelerometer: "
	       "TUM's /imu)");
}

void BagImportParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg)
{
	checkExperimentSections(cfg);
	readOptions(*this, cfg, "import_bag");
	{
		ConfigSection s(cfg, "import_bag");
		if (accelLabel.empty()) s.fail("accel_label", "must not be empty");
		if (depthUnits != 0 && depthUnits < 1e-6)
			s.fail("depth_units",
			       "must be 0 (the recording's) or in [1e-6, 0.1] m");
		if (accelLabel.find("SYNTH") != std::string::npos)
			s.fail("accel_label",
			       "'" + accelLabel +
			           "': a bag's accelerometer is a real sensor; a label "
			           "with SYNTH is the synthetic IMU's");
	}
	ConfigSection cam(cfg, "camera");
	if (cam.has("depth_scale"))
		cam.fail("depth_scale",
		         "does not apply to a bag: its depth encoding says the "
		         "unit (16UC1 millimetres, 32FC1 metres; ROS REP 118)");
	// as bims-run reads it: the six together or none (then the bag's own)
	sensors::CameraParams c;
	c.loadFromConfigFile(cfg, "camera");
	if (c.given)
	{
		camera = c.tcamera();
		cameraFrom = "[camera] of " + cam.file();
	}
	eval::loadImportLabels(cfg, rgbdLabel, imuLabel);
	images.loadFromConfigFile(cfg, "input");
}

}  // namespace bims::bag
