// bims-import-bag's speed: the bundled sample's frames upscaled to 640x480
// (depth nearest, colour bilinear; the camera scaled), repeated to N frames
// with their IMU, written as realsense-ros bags (uncompressed, LZ4, BZ2)
// and, when node and the tests' ROS 2 writer are installed
// (tests/ros2_writer), as a realsense-ros 4.x ROS 2 bag in MCAP with zstd
// chunks of 768 KiB (rosbag2's default), then imported
// (bims::bag::importBag) into a plain and a gzip rawlog. Prints the frames
// per second of each, the best of 3 runs.
//   build/bin/bag_import_speed [N=300] [WORK_DIR=/tmp/bims_bag_bench]
#include <bims/bag/bag_import.h>
#include <bims/io/rawlog.h>
#include <bims_test/bag_writer.h>
#include <mrpt/obs/CObservationIMU.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>

namespace
{
using namespace bims;
using mrpt::obs::CObservation3DRangeScan;
using mrpt::obs::CObservationIMU;

/** \a f at twice its size (640x480 for the sample's 320x240). */
CObservation3DRangeScan::Ptr upscaled(const CObservation3DRangeScan& f,
                                      double shift)
{
	auto o = CObservation3DRangeScan::Create();
	*o = f;
	const int W = 2 * static_cast<int>(f.rangeImage.cols()),
	          H = 2 * static_cast<int>(f.rangeImage.rows());
	o->rangeImage_setSize(H, W);
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
			o->rangeImage(v, u) = f.rangeImage(v / 2, u / 2);
	cv::Mat bgr;
	cv::resize(f.intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY), bgr,
	           cv::Size(W, H), 0, 0, cv::INTER_LINEAR);
	o->intensityImage = mrpt::img::CImage(bgr, mrpt::img::DEEP_COPY);
	o->cameraParams.scaleToResolution(W, H);
	o->cameraParamsIntensity = o->cameraParams;
	o->timestamp =
	    mrpt::Clock::fromDouble(mrpt::Clock::toDouble(f.timestamp) + shift);
	return o;
}
/** \a t as ROS 2's builtin_interfaces/Time. */
nlohmann::json rosStamp(double t)
{
	const ros::Time r = test::rosTime(t);
	return {{"stamp", {{"sec", r.sec}, {"nanosec", r.nsec}}},
	        {"frame_id", "camera"}};
}

/** \a frames and \a imu as a realsense-ros 4.x ROS 2 bag at \a path (MCAP,
 * zstd chunks) by the tests' independent writer; false when node or its
 * packages are not installed. */
bool writeRos2Bag(const std::string& path,
                  const std::vector<CObservation3DRangeScan::Ptr>& frames,
                  const std::vector<CObservationIMU::Ptr>& imu)
{
	const std::string writer = BIMS_ROS2_WRITER_DIR;
	if (!std::filesystem::exists(writer + "/node_modules/@mcap/core") ||
	    std::system("node --version > /dev/null 2>&1") != 0)
		return false;
	using json = nlohmann::json;
	json spec;
	spec["out"] = path;
	spec["compression"] = "zstd";
	spec["chunkSize"] = 768 * 1024;
	spec["blob"] = path + ".blob";
	for (const char* t : {"/camera/camera/aligned_depth_to_color/image_raw",
	                      "/camera/camera/color/image_raw"})
		spec["topics"].push_back(
		    {{"name", t}, {"type", "sensor_msgs/msg/Image"}});
	spec["topics"].push_back({{"name", "/camera/camera/color/camera_info"},
	                          {"type", "sensor_msgs/msg/CameraInfo"}});
	spec["topics"].push_back(
	    {{"name", "/camera/camera/imu"}, {"type", "sensor_msgs/msg/Imu"}});
	std::ofstream blob(path + ".blob", std::ios::binary);
	size_t at = 0;
	struct Msg
	{
		double t;
		json m;
	};
	std::vector<Msg> msgs;
	auto logTime = [](double t)
	{
		const ros::Time r = test::rosTime(t);
		return std::to_string(uint64_t(r.sec) * 1000000000u + r.nsec);
	};
	for (const auto& f : frames)
	{
		const double t = mrpt::Clock::toDouble(f->timestamp);
		const int W = int(f->rangeImage.cols()), H = int(f->rangeImage.rows());
		std::vector<uint16_t> depth(size_t(W) * H);
		for (int v = 0; v < H; v++)
			for (int u = 0; u < W; u++)
				depth[size_t(v) * W + u] = f->rangeImage(v, u);
		cv::Mat rgb;
		cv::cvtColor(
		    f->intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY), rgb,
		    cv::COLOR_BGR2RGB);
		blob.write(reinterpret_cast<const char*>(depth.data()),
		           std::streamsize(depth.size() * 2));
		blob.write(reinterpret_cast<const char*>(rgb.data),
		           std::streamsize(rgb.total() * 3));
		auto image = [&](const char* enc, int bpp)
		{
			return json{{"header", rosStamp(t)},
			            {"height", H},
			            {"width", W},
			            {"encoding", enc},
			            {"is_bigendian", 0},
			            {"step", W * bpp}};
		};
		msgs.push_back({t,
		                {{"topic", 0},
		                 {"logTime", logTime(t)},
		                 {"msg", image("16UC1", 2)},
		                 {"data", {at, depth.size() * 2}}}});
		at += depth.size() * 2;
		msgs.push_back({t,
		                {{"topic", 1},
		                 {"logTime", logTime(t)},
		                 {"msg", image("rgb8", 3)},
		                 {"data", {at, rgb.total() * 3}}}});
		at += rgb.total() * 3;
		const auto& c = f->cameraParams;
		msgs.push_back(
		    {t,
		     {{"topic", 2},
		      {"logTime", logTime(t)},
		      {"msg",
		       {{"header", rosStamp(t)},
		        {"height", H},
		        {"width", W},
		        {"distortion_model", "plumb_bob"},
		        {"d", json::array()},
		        {"k", {c.fx(), 0, c.cx(), 0, c.fy(), c.cy(), 0, 0, 1}},
		        {"r", {1, 0, 0, 0, 1, 0, 0, 0, 1}},
		        {"p", {c.fx(), 0, c.cx(), 0, 0, c.fy(), c.cy(), 0, 0, 0, 1, 0}},
		        {"binning_x", 0},
		        {"binning_y", 0},
		        {"roi",
		         {{"x_offset", 0},
		          {"y_offset", 0},
		          {"height", 0},
		          {"width", 0},
		          {"do_rectify", false}}}}}}});
	}
	const json zero = {0, 0, 0, 0, 0, 0, 0, 0, 0},
	           none = {-1, 0, 0, 0, 0, 0, 0, 0, 0};
	for (const auto& m : imu)
	{
		using namespace mrpt::obs;
		const double t = mrpt::Clock::toDouble(m->timestamp);
		auto v = [&](TIMUDataIndex x, TIMUDataIndex y, TIMUDataIndex z) {
			return json{{"x", m->get(x)}, {"y", m->get(y)}, {"z", m->get(z)}};
		};
		msgs.push_back(
		    {t,
		     {{"topic", 3},
		      {"logTime", logTime(t)},
		      {"msg",
		       {{"header", rosStamp(t)},
		        {"orientation", {{"x", 0}, {"y", 0}, {"z", 0}, {"w", 1}}},
		        {"orientation_covariance", none},
		        {"angular_velocity", v(IMU_WX, IMU_WY, IMU_WZ)},
		        {"angular_velocity_covariance", zero},
		        {"linear_acceleration", v(IMU_X_ACC, IMU_Y_ACC, IMU_Z_ACC)},
		        {"linear_acceleration_covariance", zero}}}}});
	}
	std::stable_sort(msgs.begin(), msgs.end(),
	                 [](const Msg& a, const Msg& b) { return a.t < b.t; });
	for (auto& m : msgs) spec["messages"].push_back(std::move(m.m));
	blob.close();
	std::ofstream(path + ".json") << spec.dump();
	const int rc = std::system(
	    ("node '" + writer + "/write_bag.mjs' '" + path + ".json'").c_str());
	std::filesystem::remove(path + ".blob");
	std::filesystem::remove(path + ".json");
	return rc == 0;
}
}  // namespace

int main(int argc, char** argv)
{
	const size_t n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 300;
	const std::string dir = argc > 2 ? argv[2] : "/tmp/bims_bag_bench";
	std::filesystem::create_directories(dir);

	std::vector<CObservation3DRangeScan::Ptr> base;
	std::vector<CObservationIMU::Ptr> baseImu;
	{
		RawlogReader in(std::string(BIMS_SOURCE_DIR) +
		                "/rawlogs/pendulum_slow.rawlog");
		while (auto o = in.next())
			if (auto f = std::dynamic_pointer_cast<CObservation3DRangeScan>(o))
			{
				f->load();
				base.push_back(f);
			}
			else if (auto m = std::dynamic_pointer_cast<CObservationIMU>(o))
				baseImu.push_back(m);
	}
	const double span = mrpt::Clock::toDouble(base.back()->timestamp) -
	                    mrpt::Clock::toDouble(base.front()->timestamp) +
	                    1.0 / 30;
	std::vector<CObservation3DRangeScan::Ptr> frames;
	std::vector<CObservationIMU::Ptr> imu;
	for (size_t k = 0; frames.size() < n; k++)
	{
		const double shift = double(k / base.size()) * span;
		frames.push_back(upscaled(*base[k % base.size()], shift));
		if (k % base.size() == 0)
			for (const auto& m : baseImu)
			{
				auto c = CObservationIMU::Create();
				*c = *m;
				c->timestamp = mrpt::Clock::fromDouble(
				    mrpt::Clock::toDouble(m->timestamp) + shift);
				imu.push_back(c);
			}
	}
	std::printf("%zu frames of %ux%u, %zu IMU samples\n", frames.size(),
	            frames[0]->rangeImage.cols(), frames[0]->rangeImage.rows(),
	            imu.size());
	std::printf("%-13s %10s %12s %12s\n", "bag", "MB", "plain fps",
	            "gzip-1 fps");
	const struct
	{
		const char* name;
		rosbag::compression::CompressionType c;
	} kinds[] = {{"uncompressed", rosbag::compression::Uncompressed},
	             {"lz4", rosbag::compression::LZ4},
	             {"bz2", rosbag::compression::BZ2}};
	auto measure = [&](const char* name, const std::string& bag)
	{
		double fps[2] = {0, 0};
		for (int gz : {0, 1})
			for (int run = 0; run < 3; run++)
			{
				bag::BagImportOptions o;
				o.gzLevel = gz;
				const auto t0 = std::chrono::steady_clock::now();
				const auto sum = bag::importBag({bag}, dir + "/out.rawlog",
				                                bag::BagImportParams{}, o);
				const double s = std::chrono::duration<double>(
				                     std::chrono::steady_clock::now() - t0)
				                     .count();
				fps[gz] = std::max(fps[gz], double(sum.frames) / s);
			}
		std::printf("%-13s %10.1f %12.1f %12.1f\n", name,
		            double(std::filesystem::file_size(bag)) / 1e6, fps[0],
		            fps[1]);
	};
	for (const auto& k : kinds)
	{
		test::BagSpec spec;
		spec.compression = k.c;
		spec.frames = frames.size();
		const std::string bag = dir + "/" + k.name + ".bag";
		test::writeBag(bag, spec, frames, imu);
		measure(k.name, bag);
	}
	const std::string mcap = dir + "/ros2_zstd.mcap";
	if (writeRos2Bag(mcap, frames, imu))
		measure("ros2 mcap zstd", mcap);
	else
		std::printf(
		    "ros2 mcap zstd: skipped (node or tests/ros2_writer's npm "
		    "packages are not installed)\n");
	return 0;
}
