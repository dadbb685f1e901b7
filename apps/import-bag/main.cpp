// bims-import-bag BAG... -o OUT.rawlog [--layout tum|realsense|rs-sdk|auto]
//   [-c CONFIG.ini] [--depth-units M] [--max-frames N] [--gz L] [--topics]
//   [-q]
// Converts ROS 1 and ROS 2 bags (depth and colour sensor_msgs/Image or
// CompressedImage, CameraInfo, Imu, MagneticField) into a bims rawlog. See
// docs/import-bag.md.
#include <bims/apps/app.h>
#include <bims/apps/bag_import_run.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-import-bag",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "Import ROS 1 bags, ROS 2 bags (a folder with its "
		        "metadata.yaml, or one .mcap or .db3 file) (depth and colour "
		        "sensor_msgs/Image, or "
		        "sensor_msgs/CompressedImage as image_transport writes it: "
		        "JPEG or PNG colour, compressedDepth PNG or RVL depth; their "
		        "CameraInfo, sensor_msgs/Imu or separate accelerometer and "
		        "gyro topics, MagneticField) into a rawlog of RGB-D frames "
		        "and IMU samples. Depth and colour are paired by stamp; the "
		        "stamps are the messages' header stamps. Several bags are "
		        "read as one recording.",
		        ' ', bims::version());
		    TCLAP::UnlabeledMultiArg<std::string> bags(
		        "BAG",
		        "ROS 1 bag files (.bag), ROS 2 bag folders, .mcap or .db3 "
		        "files",
		        true, "BAG", cmd);
		    TCLAP::ValueArg<std::string> out("o", "out", "output rawlog", false,
		                                     "", "OUT.rawlog", cmd);
		    TCLAP::ValueArg<std::string> layout(
		        "", "layout",
		        "preset topics: realsense (realsense-ros, aligned depth; ROS "
		        "2: realsense-ros 4.x's /camera/camera/...), tum "
		        "(TUM RGB-D's bags), auto (default: the first whose depth "
		        "topic the bag has), rs-sdk (the RealSense SDK's own "
		        "recordings: RealSense Viewer, rs-record; writes "
		        "OUT_gt/calibration.ini); a preset image topic the bag lacks "
		        "is read from its /compressed or /compressedDepth republished "
		        "topic when the bag has that",
		        false, "", "realsense|tum|rs-sdk|auto", cmd);
		    TCLAP::ValueArg<double> depthUnits(
		        "", "depth-units",
		        "rs-sdk: metres per unit of the recording's depth, replacing "
		        "its Depth Units option (needed when it has none)",
		        false, 0, "M", cmd);
		    TCLAP::ValueArg<std::string> config(
		        "c", "config",
		        "experiment .ini: [import_bag] topics and pairing, [camera] "
		        "intrinsics over the bag's CameraInfo, [sensors] labels, "
		        "[input] the limits of compressed images (e.g. the preset "
		        "realsense.ini of share/bims)",
		        false, "", "CONFIG.ini", cmd);
		    TCLAP::ValueArg<long> maxFrames(
		        "", "max-frames", "import only the first N frames (0 = all)",
		        false, 0, "N", cmd);
		    TCLAP::ValueArg<int> gz(
		        "", "gz", "gzip level of the rawlog, 0 = plain (default 1)",
		        false, 1, "L", cmd);
		    TCLAP::SwitchArg topics(
		        "", "topics", "list the bags' topics and types, import nothing",
		        cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    bims::apps::BagImportRunOptions o;
		    o.bags = bags.getValue();
		    o.out = out.getValue();
		    o.config = bims::givenValue(config);
		    o.layout = bims::givenValue(layout);
		    o.depthUnits = bims::givenValue(depthUnits);
		    o.max_frames = static_cast<size_t>(
		        bims::inRange(maxFrames, 0L, 100000000L, "0 = all"));
		    o.gz = gz.getValue();
		    o.progress = !quiet.getValue();
		    o.listTopics = topics.getValue();
		    return bims::apps::runBagImport(o);
	    });
}
