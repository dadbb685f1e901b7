// bims-import-bag on ROS 2 bags written by an independent writer, not by
// bims (tests/ros2_writer: MCAP by @mcap/core, CDR by
// @foxglove/rosmsg2-serialization, zstd and lz4 chunks; .db3 by Python's
// sqlite3 module): the Bonn slice as a TUM-layout ROS 2 bag gives the
// rawlog of its TUM folder byte for byte, in every storage and
// compression; realsense-ros 4.x's topic names; and the bad input users
// meet. Skipped (not failed) without node, the writer's npm packages or
// Python's sqlite3 (scripts/install-deps.sh installs them).
#include <bims/bag/bag_import.h>
#include <bims/eval/tum_import.h>
#include <bims/io/rawlog.h>
#include <bims_test/bag_writer.h>
#include <bims_test/data.h>
#include <bims_test/error_of.h>
#include <bims_test/run_command.h>
#include <bims_test/text.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <mrpt/core/format.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>

#include <bims/bag/cdr.h>

namespace
{
namespace fs = std::filesystem;
using namespace bims;
using json = nlohmann::json;

const std::string kImport = std::string(BIMS_BIN_DIR) + "/bims-import-bag";
const std::string kWriter = BIMS_ROS2_WRITER_DIR;

/** Why the independent writer cannot run here (empty: it can). */
std::string writerMissing()
{
	if (test::runCommand("node --version").code != 0)
		return "node is not installed (scripts/install-deps.sh)";
	for (const char* p : {"@mcap/core", "@foxglove/rosmsg2-serialization",
	                      "@foxglove/rosmsg", "@foxglove/wasm-zstd", "lz4js"})
		if (!fs::exists(kWriter + "/node_modules/" + p + "/package.json"))
			return std::string("the writer's npm package ") + p +
			       " is not installed (scripts/install-deps.sh runs npm ci "
			       "in tests/ros2_writer)";
	if (test::runCommand("python3 -c 'import sqlite3'").code != 0)
		return "Python 3's sqlite3 module is missing";
	return "";
}

#define SKIP_WITHOUT_WRITER()                                      \
	do                                                             \
	{                                                              \
		const std::string why = writerMissing();                   \
		if (!why.empty()) GTEST_SKIP() << "ROS 2 writer: " << why; \
	} while (0)

void writeText(const std::string& path, const std::string& text)
{
	std::ofstream(path, std::ios::binary) << text;
}

std::string errorOf(const std::function<void()>& f)
{
	return bims::test::errorOf(f, "(no error)");
}

/** A ROS 2 bag to write: the writer's spec and the images' bytes. */
struct BagSpec
{
	json spec;
	std::string blob;

	size_t topic(const std::string& name, const std::string& type)
	{
		spec["topics"].push_back({{"name", name}, {"type", type}});
		return spec["topics"].size() - 1;
	}
	/** Adds \a m on topic \a t at \a stamp ("sec.frac"), its stamp's
	 * decimals as the header's and the log time; \a data into the blob. */
	json& add(size_t t, const std::string& stamp, json m,
	          const std::string& data = {})
	{
		const size_t dot = stamp.find('.');
		std::string frac = stamp.substr(dot + 1);
		frac.resize(9, '0');
		const long long sec = std::stoll(stamp.substr(0, dot)),
		                nsec = std::stoll(frac);
		m["header"] = {{"stamp", {{"sec", sec}, {"nanosec", nsec}}},
		               {"frame_id", "camera"}};
		json msg = {{"topic", t},
		            {"logTime", std::to_string(sec * 1000000000LL + nsec)},
		            {"msg", m}};
		if (!data.empty() || m.contains("step"))
		{
			msg["data"] = {blob.size(), data.size()};
			blob += data;
		}
		spec["messages"].push_back(msg);
		return spec["messages"].back();
	}
	/** The messages in log-time order (as a recorder writes them). */
	void sortByTime()
	{
		auto& m = spec["messages"];
		std::stable_sort(
		    m.begin(), m.end(),
		    [](const json& a, const json& b)
		    {
			    return std::stoull(a["logTime"].get<std::string>()) <
			           std::stoull(b["logTime"].get<std::string>());
		    });
	}
};

/** Runs the writer on \a b: an MCAP file (\a compression "", "zstd",
 * "lz4" or another name) at \a out. */
void writeMcap(BagSpec b, const std::string& out,
               const std::string& compression = "", bool summary = true,
               size_t chunkSize = 1 << 20, bool chunks = true)
{
	b.spec["out"] = out;
	b.spec["useChunks"] = chunks;
	b.spec["compression"] = compression;
	b.spec["summary"] = summary;
	b.spec["chunkSize"] = chunkSize;
	b.spec["blob"] = out + ".blob";
	writeText(out + ".blob", b.blob);
	writeText(out + ".json", b.spec.dump());
	const auto r = test::runCommand("node '" + kWriter + "/write_bag.mjs' '" +
	                                out + ".json'");
	ASSERT_EQ(r.code, 0) << r.out;
	fs::remove(out + ".blob");
	fs::remove(out + ".json");
}

/** Runs the writer and write_db3.py on \a b: a .db3 at \a out (without the
 * table \a without, when given). */
void writeDb3(BagSpec b, const std::string& out,
              const std::string& without = "")
{
	const std::string dump = out + ".dump";
	b.spec["out"] = dump;
	b.spec["format"] = "dump";
	b.spec["blob"] = out + ".blob";
	writeText(out + ".blob", b.blob);
	writeText(out + ".json", b.spec.dump());
	auto r = test::runCommand("node '" + kWriter + "/write_bag.mjs' '" + out +
	                          ".json'");
	ASSERT_EQ(r.code, 0) << r.out;
	fs::remove(out);
	r = test::runCommand("python3 '" + kWriter + "/write_db3.py' '" + dump +
	                     "' '" + out + "'" +
	                     (without.empty() ? "" : " --without " + without));
	ASSERT_EQ(r.code, 0) << r.out;
	for (const char* e : {".blob", ".json", ".dump.json", ".dump.bin"})
		fs::remove(out + e);
}

/** The first \a n rows of a TUM list file (comments kept). */
std::vector<std::pair<std::string, std::string>> tumRows(
    const std::string& file, size_t n, std::string* text = nullptr)
{
	std::ifstream in(file);
	std::vector<std::pair<std::string, std::string>> rows;
	std::string line;
	while (std::getline(in, line) && rows.size() < n)
	{
		if (text) *text += line + "\n";
		if (line.empty() || line[0] == '#') continue;
		std::istringstream s(line);
		std::string t, f;
		s >> t >> f;
		rows.emplace_back(t, f);
	}
	return rows;
}

// the Bonn intrinsics (its README)
constexpr double kFx = 542.822841, kFy = 542.576870, kCx = 315.593520,
                 kCy = 237.756098;

/** The first \a n depth and colour images of the Bonn slice as a TUM
 * folder at \a dir (its images linked), with an accelerometer.txt of the
 * tests' own (Bonn has no IMU) at 100 Hz over the frames' span. */
void bonnFolder(const std::string& dir, size_t n)
{
	fs::create_directories(dir);
	for (const char* sub : {"rgb", "depth"})
		fs::create_directory_symlink(fs::path(test::kBonnCrowd) / sub,
		                             fs::path(dir) / sub);
	for (const char* list : {"rgb.txt", "depth.txt"})
	{
		std::string text;
		tumRows(test::kBonnCrowd + "/" + list, n, &text);
		writeText(dir + "/" + list, text);
	}
	const auto depth = tumRows(dir + "/depth.txt", n);
	const double t0 = std::stod(depth.front().first),
	             t1 = std::stod(depth.back().first);
	std::ofstream acc(dir + "/accelerometer.txt");
	acc << "# accelerometer data\n# timestamp ax ay az\n";
	const auto s0 = static_cast<long long>(std::floor(t0 * 100)) - 2;
	for (long long k = s0; k <= static_cast<long long>(t1 * 100) + 2; k++)
		acc << mrpt::format("%lld.%02lld0000 %.17g %.17g %.17g\n", k / 100,
		                    k % 100, 0.3 * std::sin(0.1 * double(k)),
		                    -9.81 + 0.01 * double(k % 7),
		                    0.2 * std::cos(0.05 * double(k)));
}

/** The TUM folder \a dir as a ROS 2 bag of TUM's layout: depth in metres
 * (32FC1, NaN for no reading), colour rgb8, CameraInfo, the accelerometer
 * as an Imu without a gyro (its covariance -1). */
BagSpec tumLayoutBag(const std::string& dir, size_t n)
{
	BagSpec b;
	const size_t depthT =
	                 b.topic("/camera/depth/image", "sensor_msgs/msg/Image"),
	             colourT = b.topic("/camera/rgb/image_color",
	                               "sensor_msgs/msg/Image"),
	             infoT = b.topic("/camera/rgb/camera_info",
	                             "sensor_msgs/msg/CameraInfo"),
	             imuT = b.topic("/imu", "sensor_msgs/msg/Imu");
	for (const auto& [t, f] : tumRows(dir + "/depth.txt", n))
	{
		const cv::Mat png = cv::imread(dir + "/" + f, cv::IMREAD_UNCHANGED);
		cv::Mat m(png.rows, png.cols, CV_32FC1);
		for (int v = 0; v < png.rows; v++)
			for (int u = 0; u < png.cols; u++)
			{
				const uint16_t d = png.at<uint16_t>(v, u);
				m.at<float>(v, u) =
				    d == 0 ? std::numeric_limits<float>::quiet_NaN()
				           : static_cast<float>(d / 5000.0);
			}
		b.add(
		    depthT, t,
		    {{"height", m.rows},
		     {"width", m.cols},
		     {"encoding", "32FC1"},
		     {"is_bigendian", 0},
		     {"step", m.cols * 4}},
		    std::string(reinterpret_cast<const char*>(m.data), m.total() * 4));
		b.add(infoT, t,
		      {{"height", m.rows},
		       {"width", m.cols},
		       {"distortion_model", "plumb_bob"},
		       {"d", {0, 0, 0, 0, 0}},
		       {"k", {kFx, 0, kCx, 0, kFy, kCy, 0, 0, 1}},
		       {"r", {1, 0, 0, 0, 1, 0, 0, 0, 1}},
		       {"p", {kFx, 0, kCx, 0, 0, kFy, kCy, 0, 0, 0, 1, 0}},
		       {"binning_x", 0},
		       {"binning_y", 0},
		       {"roi",
		        {{"x_offset", 0},
		         {"y_offset", 0},
		         {"height", 0},
		         {"width", 0},
		         {"do_rectify", false}}}});
	}
	for (const auto& [t, f] : tumRows(dir + "/rgb.txt", n))
	{
		cv::Mat bgr = cv::imread(dir + "/" + f, cv::IMREAD_COLOR), rgb;
		cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
		b.add(colourT, t,
		      {{"height", rgb.rows},
		       {"width", rgb.cols},
		       {"encoding", "rgb8"},
		       {"is_bigendian", 0},
		       {"step", rgb.cols * 3}},
		      std::string(reinterpret_cast<const char*>(rgb.data),
		                  rgb.total() * 3));
	}
	std::ifstream acc(dir + "/accelerometer.txt");
	std::string line;
	const json none = {-1, 0, 0, 0, 0, 0, 0, 0, 0},
	           zero = {0, 0, 0, 0, 0, 0, 0, 0, 0};
	while (std::getline(acc, line))
	{
		if (line.empty() || line[0] == '#') continue;
		std::istringstream s(line);
		std::string t;
		double a[3];
		s >> t >> a[0] >> a[1] >> a[2];
		b.add(imuT, t,
		      {{"orientation", {{"x", 0}, {"y", 0}, {"z", 0}, {"w", 1}}},
		       {"orientation_covariance", none},
		       {"angular_velocity", {{"x", 0}, {"y", 0}, {"z", 0}}},
		       {"angular_velocity_covariance", none},
		       {"linear_acceleration", {{"x", a[0]}, {"y", a[1]}, {"z", a[2]}}},
		       {"linear_acceleration_covariance", zero}});
	}
	b.sortByTime();
	return b;
}

bag::BagImportSummary import(const std::string& path, const std::string& out,
                             bag::BagImportParams p = {})
{
	bag::BagImportOptions o;
	o.gzLevel = 0;
	return bag::importBag({path}, out, p, o);
}

/** The TUM folder's import, as bims-import-tum makes it. */
void importFolder(const std::string& dir, const std::string& out)
{
	eval::ImportParams tp;
	tp.camera.fx = kFx;
	tp.camera.fy = kFy;
	tp.camera.cx = kCx;
	tp.camera.cy = kCy;
	tp.camera.width = 640;
	tp.camera.height = 480;
	eval::ImportOptions to;
	to.gzLevel = 0;
	eval::importTum(dir, out, tp, to);
}

/** The Bonn slice's first frames: its folder, its rawlog and its bag. */
struct Bonn
{
	std::string dir, rawlog;
	BagSpec bag;
};
constexpr size_t kBonnFrames = 6;

const Bonn& bonn()
{
	static const Bonn b = []
	{
		Bonn r;
		const auto d = test::freshTmpDir("bims_ros2", "bonn");
		r.dir = d + "/folder";
		bonnFolder(r.dir, kBonnFrames);
		r.rawlog = d + "/folder.rawlog";
		importFolder(r.dir, r.rawlog);
		r.bag = tumLayoutBag(r.dir, kBonnFrames);
		return r;
	}();
	return b;
}

#define SKIP_WITHOUT_BONN()                                        \
	do                                                             \
	{                                                              \
		if (!fs::exists(test::kBonnCrowd + "/rgb.txt"))            \
			GTEST_SKIP() << "the shared Bonn slice is not there: " \
			             << test::kBonnCrowd;                      \
	} while (0)

TEST(Ros2Import, TheBonnSliceAsATumLayoutBagGivesItsFoldersRawlogByteForByte)
{
	SKIP_WITHOUT_WRITER();
	SKIP_WITHOUT_BONN();
	const auto d = test::freshTmpDir("bims_ros2", "same");
	const std::string want = test::fileText(bonn().rawlog);
	ASSERT_GT(want.size(), 1000000u);
	bag::BagImportParams p;
	p.layout = bag::BagLayout::Tum;
	auto check = [&](const std::string& path, const std::string& what)
	{
		const std::string out = d + "/" + what + ".rawlog";
		const auto sum = import(path, out, p);
		EXPECT_GE(sum.frames, kBonnFrames - 2) << what;
		EXPECT_EQ(sum.depthEncoding, "32FC1") << what;
		EXPECT_GT(sum.accelOnly, 0u) << what;
		EXPECT_EQ(sum.accelOnly, sum.imu) << what;
		EXPECT_TRUE(test::fileText(out) == want)
		    << what << ": " << fs::file_size(out) << " vs " << want.size()
		    << " bytes";
	};
	for (const std::string c : {"", "zstd", "lz4"})
	{
		const std::string path =
		    d + "/bonn" + (c.empty() ? "" : "_" + c) + ".mcap";
		// chunks of ~1 MB: several per bag, images split across them
		writeMcap(bonn().bag, path, c);
		check(path, "mcap " + (c.empty() ? std::string("none") : c));
	}
	writeDb3(bonn().bag, d + "/bonn.db3");
	check(d + "/bonn.db3", "db3");
	// a ROS 2 bag folder: its metadata.yaml names its files
	fs::create_directories(d + "/folder_bag");
	writeMcap(bonn().bag, d + "/folder_bag/folder_bag_0.mcap", "zstd");
	writeText(d + "/folder_bag/metadata.yaml",
	          "rosbag2_bagfile_information:\n  version: 8\n"
	          "  storage_identifier: mcap\n"
	          "  relative_file_paths:\n    - folder_bag_0.mcap\n"
	          "  compression_format: \"\"\n  compression_mode: \"\"\n");
	check(d + "/folder_bag", "folder");
}

/** The topic names of a small bag. */
struct Names
{
	std::string depth, colour, info, accel, gyro;
	std::string depthEncoding = "32FC1";
};
const Names kTum = {"/camera/depth/image",
                    "/camera/rgb/image_color",
                    "/camera/rgb/camera_info",
                    "",
                    "",
                    "32FC1"};
const Names kRealSense2 = {"/camera/camera/aligned_depth_to_color/image_raw",
                           "/camera/camera/color/image_raw",
                           "/camera/camera/color/camera_info",
                           "/camera/camera/accel/sample",
                           "/camera/camera/gyro/sample",
                           "16UC1"};
constexpr int kW = 32, kH = 24;

std::string stampOf(size_t k)
{
	return mrpt::format("100.%06zu", 33000 * k + 1000);
}

json cameraInfo()
{
	return {{"height", kH},
	        {"width", kW},
	        {"distortion_model", "plumb_bob"},
	        {"d", json::array()},
	        {"k", {30.0, 0, 15.5, 0, 30.0, 11.5, 0, 0, 1}},
	        {"r", {1, 0, 0, 0, 1, 0, 0, 0, 1}},
	        {"p", {30.0, 0, 15.5, 0, 0, 30.0, 11.5, 0, 0, 0, 1, 0}},
	        {"binning_x", 0},
	        {"binning_y", 0},
	        {"roi",
	         {{"x_offset", 0},
	          {"y_offset", 0},
	          {"height", 0},
	          {"width", 0},
	          {"do_rectify", false}}}};
}

/** \a n frames of 32x24 (depth, colour of byte value 0x40 + frame, its
 * CameraInfo), with accelerometer and gyro at 200 Hz when \a names has
 * them; frame \a mark's colour is all 0xAB (found in the file). */
BagSpec smallBag(size_t n, const Names& names = kTum, size_t mark = 1000)
{
	BagSpec b;
	const size_t dT = b.topic(names.depth, "sensor_msgs/msg/Image"),
	             cT = b.topic(names.colour, "sensor_msgs/msg/Image"),
	             iT = b.topic(names.info, "sensor_msgs/msg/CameraInfo");
	const bool metres = names.depthEncoding == "32FC1";
	for (size_t k = 0; k < n; k++)
	{
		std::string depth,
		    colour(kW * kH * 3, static_cast<char>(k == mark ? 0xAB : 0x40 + k));
		for (int i = 0; i < kW * kH; i++)
		{
			const uint16_t mm = static_cast<uint16_t>(800 + 3 * i + 10 * k);
			if (metres)
			{
				const float m = mm / 1000.0f;
				depth.append(reinterpret_cast<const char*>(&m), 4);
			}
			else
				depth.append(reinterpret_cast<const char*>(&mm), 2);
		}
		const std::string t = stampOf(k);
		b.add(dT, t,
		      {{"height", kH},
		       {"width", kW},
		       {"encoding", names.depthEncoding},
		       {"is_bigendian", 0},
		       {"step", kW * (metres ? 4 : 2)}},
		      depth);
		b.add(cT, t,
		      {{"height", kH},
		       {"width", kW},
		       {"encoding", "rgb8"},
		       {"is_bigendian", 0},
		       {"step", kW * 3}},
		      colour);
		b.add(iT, t, cameraInfo());
	}
	if (!names.accel.empty())
	{
		const size_t aT = b.topic(names.accel, "sensor_msgs/msg/Imu"),
		             gT = b.topic(names.gyro, "sensor_msgs/msg/Imu");
		const json none = {-1, 0, 0, 0, 0, 0, 0, 0, 0},
		           zero = {0, 0, 0, 0, 0, 0, 0, 0, 0};
		for (size_t k = 0; k < n * 7; k++)
			for (const bool gyro : {false, true})
				b.add(
				    gyro ? gT : aT,
				    mrpt::format("100.%06zu", 5000 * k + (gyro ? 2000 : 0)),
				    {{"orientation", {{"x", 0}, {"y", 0}, {"z", 0}, {"w", 1}}},
				     {"orientation_covariance", none},
				     {"angular_velocity",
				      {{"x", gyro ? 0.01 * double(k) : 0.0},
				       {"y", 0.2},
				       {"z", 0}}},
				     {"angular_velocity_covariance", gyro ? zero : none},
				     {"linear_acceleration",
				      {{"x", 0}, {"y", gyro ? 0.0 : -9.8}, {"z", 0.1}}},
				     {"linear_acceleration_covariance", gyro ? none : zero}});
	}
	b.sortByTime();
	return b;
}

/** The frames of a rawlog: stamp and range image of each. */
std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> framesOf(
    const std::string& rawlog)
{
	std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> out;
	RawlogReader in(rawlog);
	while (auto o = in.next())
		if (auto f =
		        std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
		            o))
			out.push_back(f);
	return out;
}

/** \a a's frames are the first of \a b's, pixel for pixel. */
void expectFirstFrames(const std::string& a, const std::string& b)
{
	const auto fa = framesOf(a), fb = framesOf(b);
	ASSERT_LE(fa.size(), fb.size());
	for (size_t k = 0; k < fa.size(); k++)
	{
		EXPECT_EQ(fa[k]->timestamp, fb[k]->timestamp) << k;
		EXPECT_TRUE(
		    (fa[k]->rangeImage.array() == fb[k]->rangeImage.array()).all())
		    << k;
	}
}

bool has(const std::string& text, const std::string& part)
{
	return text.find(part) != std::string::npos;
}

/** \a raw (smallBag(n, kRealSense2)) with its depth and colour as
 * image_transport republishes them: compressedDepth (\a codec "png" or
 * "rvl") of the 16UC1 millimetres, PNG colour ("rgb8; png compressed
 * bgr8"), on the raw topics' /compressedDepth and /compressed. */
BagSpec compressedOf(const BagSpec& raw, const std::string& codec)
{
	BagSpec b = raw;
	b.blob.clear();
	b.spec["topics"][0]["name"] =
	    raw.spec["topics"][0]["name"].get<std::string>() + "/compressedDepth";
	b.spec["topics"][1]["name"] =
	    raw.spec["topics"][1]["name"].get<std::string>() + "/compressed";
	for (const int t : {0, 1})
		b.spec["topics"][t]["type"] = "sensor_msgs/msg/CompressedImage";
	for (auto& m : b.spec["messages"])
	{
		if (!m.contains("data")) continue;
		const std::string bytes = raw.blob.substr(m["data"][0].get<size_t>(),
		                                          m["data"][1].get<size_t>());
		const int topic = m["topic"].get<int>();
		std::string data = bytes;
		if (topic <= 1)
		{
			const int H = m["msg"]["height"], W = m["msg"]["width"];
			std::vector<uint8_t> out;
			if (topic == 0)
			{
				const float quant[2] = {0, 0};
				const cv::Mat mm(H, W, CV_16UC1,
				                 const_cast<char*>(bytes.data()));
				out = test::compressedDepthData(mm, codec, quant);
			}
			else
			{
				const cv::Mat rgb(H, W, CV_8UC3,
				                  const_cast<char*>(bytes.data()));
				cv::Mat bgr;
				cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
				cv::imencode(".png", bgr, out);
			}
			data.assign(out.begin(), out.end());
			m["msg"] = {{"format", topic == 0
			                           ? "16UC1; compressedDepth " + codec
			                           : "rgb8; png compressed bgr8"}};
		}
		m["data"] = {b.blob.size(), data.size()};
		b.blob += data;
	}
	// (the header is added back: add() set it, the compressed message
	// takes the raw one's)
	for (size_t k = 0; k < b.spec["messages"].size(); k++)
		b.spec["messages"][k]["msg"]["header"] =
		    raw.spec["messages"][k]["msg"]["header"];
	return b;
}

TEST(Ros2Import, CompressedTopicsGiveTheRawTopicsRawlogByteForByte)
{
	SKIP_WITHOUT_WRITER();
	const auto d = test::freshTmpDir("bims_ros2", "compressed");
	const BagSpec raw = smallBag(4, kRealSense2);
	writeMcap(raw, d + "/raw.mcap", "zstd");
	import(d + "/raw.mcap", d + "/raw.rawlog");
	for (const std::string codec : {"png", "rvl"})
	{
		writeMcap(compressedOf(raw, codec), d + "/" + codec + ".mcap", "zstd");
		const auto sum =
		    import(d + "/" + codec + ".mcap", d + "/" + codec + ".rawlog");
		EXPECT_EQ(sum.frames, 4u);
		EXPECT_EQ(sum.topics.depth, kRealSense2.depth + "/compressedDepth");
		EXPECT_EQ(sum.depthEncoding, "16UC1; compressedDepth " + codec);
		EXPECT_EQ(sum.colourEncoding, "rgb8; png compressed bgr8");
		EXPECT_TRUE(test::fileText(d + "/" + codec + ".rawlog") ==
		            test::fileText(d + "/raw.rawlog"))
		    << codec;
	}
}

TEST(Ros2Import, TopicsAreListedWithTheirRos2TypesAndCounts)
{
	SKIP_WITHOUT_WRITER();
	const auto d = test::freshTmpDir("bims_ros2", "topics");
	const BagSpec b = smallBag(5, kRealSense2);
	writeMcap(b, d + "/rs.mcap", "zstd");
	writeMcap(b, d + "/rs_nosummary.mcap", "lz4", false);
	writeDb3(b, d + "/rs.db3");
	// the summary's counts: its chunks (of a compression not read) are
	// not decompressed for the list
	writeMcap(b, d + "/rs_brotli.mcap", "brotli");
	for (const char* f :
	     {"rs.mcap", "rs_nosummary.mcap", "rs.db3", "rs_brotli.mcap"})
	{
		const auto r = test::runCommand("'" + kImport + "' '" + d + "/" + f +
		                                "' --topics");
		EXPECT_EQ(r.code, 0) << f << ": " << r.out;
		EXPECT_TRUE(has(r.out, "/camera/camera/color/image_raw")) << r.out;
		EXPECT_TRUE(has(r.out, "sensor_msgs/msg/Image")) << r.out;
		EXPECT_TRUE(has(r.out, "5 messages")) << r.out;
		EXPECT_TRUE(has(r.out, "35 messages")) << r.out;  // accel, gyro
	}
}

TEST(Ros2Import, RealSenseRos2TopicNamesAreThePresetsAndTheImuIsMerged)
{
	SKIP_WITHOUT_WRITER();
	const auto d = test::freshTmpDir("bims_ros2", "realsense");
	writeMcap(smallBag(6, kRealSense2), d + "/rs.mcap", "zstd");
	const auto sum = import(d + "/rs.mcap", d + "/rs.rawlog");
	EXPECT_EQ(sum.layout, bag::BagLayout::RealSense);
	EXPECT_EQ(sum.frames, 6u);
	EXPECT_EQ(sum.topics.depth, kRealSense2.depth);
	EXPECT_EQ(sum.depthEncoding, "16UC1");
	EXPECT_EQ(sum.colourEncoding, "rgb8");
	EXPECT_TRUE(sum.imuHasGyro && sum.imuHasAccel);
	EXPECT_GT(sum.imu, 20u);
	EXPECT_TRUE(has(sum.imuSource, "merged")) << sum.imuSource;
	const auto frames = framesOf(d + "/rs.rawlog");
	ASSERT_EQ(frames.size(), 6u);
	EXPECT_EQ(frames[2]->rangeImage(0, 1), 800 + 3 + 20);  // millimetres
	// the same bag as .db3: the same rawlog
	writeDb3(smallBag(6, kRealSense2), d + "/rs.db3");
	import(d + "/rs.db3", d + "/db3.rawlog");
	EXPECT_TRUE(test::fileText(d + "/rs.rawlog") ==
	            test::fileText(d + "/db3.rawlog"));

	// without align_depth: the depth alone, in its own camera (the colour,
	// not registered to it, is not attached)
	Names unaligned = kRealSense2;
	unaligned.depth = "/camera/camera/depth/image_rect_raw";
	unaligned.info = "/camera/camera/depth/camera_info";
	writeMcap(smallBag(4, unaligned), d + "/unaligned.mcap");
	const auto u = import(d + "/unaligned.mcap", d + "/unaligned.rawlog");
	EXPECT_EQ(u.layout, bag::BagLayout::RealSense);
	EXPECT_EQ(u.frames, 4u);
	EXPECT_EQ(u.topics.depth, unaligned.depth);
	EXPECT_TRUE(u.topics.colour.empty());
	EXPECT_EQ(u.cameraFrom, "CameraInfo /camera/camera/depth/camera_info");
	EXPECT_FALSE(framesOf(d + "/unaligned.rawlog")[0]->hasIntensityImage);

	// a preset topic of another type: an error naming it
	Names wrong = kRealSense2;
	BagSpec b = smallBag(3, wrong);
	b.spec["topics"][2]["type"] = "sensor_msgs/msg/Imu";
	writeMcap(b, d + "/wrong.mcap");
	const std::string e =
	    errorOf([&] { import(d + "/wrong.mcap", d + "/w.rawlog"); });
	EXPECT_TRUE(
	    has(e, "/camera/camera/color/camera_info is sensor_msgs/msg/Imu"))
	    << e;
}

TEST(Ros2Import, ABagFolderOfSeveralFilesIsReadAsOneRecording)
{
	SKIP_WITHOUT_WRITER();
	const auto d = test::freshTmpDir("bims_ros2", "split");
	const BagSpec whole = smallBag(8, kRealSense2);
	writeMcap(whole, d + "/whole.mcap", "zstd");
	import(d + "/whole.mcap", d + "/whole.rawlog");
	// ros2 bag record --max-bag-size: the messages in log-time order over
	// the files, each file with every topic
	BagSpec first = whole, second = whole;
	auto& all = whole.spec["messages"];
	first.spec["messages"] = json::array();
	second.spec["messages"] = json::array();
	for (size_t k = 0; k < all.size(); k++)
		(k < all.size() / 2 ? first : second)
		    .spec["messages"]
		    .push_back(all[k]);
	fs::create_directories(d + "/bag");
	writeMcap(first, d + "/bag/bag_0.mcap", "zstd");
	writeMcap(second, d + "/bag/bag_1.mcap", "lz4");
	writeText(d + "/bag/metadata.yaml",
	          "rosbag2_bagfile_information:\n  version: 5\n"
	          "  storage_identifier: mcap\n"
	          "  relative_file_paths:\n  - bag_0.mcap\n  - bag_1.mcap\n");
	const auto sum = import(d + "/bag", d + "/split.rawlog");
	EXPECT_EQ(sum.frames, 8u);
	EXPECT_TRUE(test::fileText(d + "/split.rawlog") ==
	            test::fileText(d + "/whole.rawlog"));
	const auto r =
	    test::runCommand("'" + kImport + "' '" + d + "/bag' --topics");
	EXPECT_TRUE(has(r.out, "8 messages") && has(r.out, "56 messages")) << r.out;
}

TEST(Ros2Import, AFolderWhoseMetadataNamesMissingFilesIsAClearError)
{
	const auto d = test::freshTmpDir("bims_ros2", "metadata");
	fs::create_directories(d + "/bag");
	auto meta = [&](const std::string& body)
	{
		writeText(d + "/bag/metadata.yaml", body);
		return errorOf([&] { import(d + "/bag", d + "/out.rawlog"); });
	};
	std::string e = meta(
	    "rosbag2_bagfile_information:\n  storage_identifier: mcap\n"
	    "  relative_file_paths:\n    - bag_0.mcap\n");
	EXPECT_TRUE(has(e, "metadata.yaml") && has(e, "bag_0.mcap") &&
	            has(e, "not in the folder"))
	    << e;
	e = meta(
	    "rosbag2_bagfile_information:\n  storage_identifier: rosbag_v2\n"
	    "  relative_file_paths:\n    - x\n");
	EXPECT_TRUE(has(e, "storage_identifier 'rosbag_v2'")) << e;
	e = meta("rosbag2_bagfile_information: [1, 2\n");
	EXPECT_TRUE(has(e, "metadata.yaml: not YAML")) << e;
	e = meta("something_else: 1\n");
	EXPECT_TRUE(has(e, "no rosbag2_bagfile_information")) << e;
	writeText(d + "/bag/bag_0.mcap", "x");
	e = meta(
	    "rosbag2_bagfile_information:\n  storage_identifier: mcap\n"
	    "  relative_file_paths: [bag_0.mcap]\n"
	    "  compression_format: zstd\n  compression_mode: FILE\n");
	EXPECT_TRUE(has(e, "compressed by rosbag2 is not read")) << e;
	// a folder without metadata.yaml
	fs::create_directories(d + "/empty");
	e = errorOf([&] { import(d + "/empty", d + "/out.rawlog"); });
	EXPECT_TRUE(has(e, "without a metadata.yaml")) << e;
	EXPECT_FALSE(fs::exists(d + "/out.rawlog"));
}

TEST(Ros2Import, McapOfAnUnknownCompressionOrAForeignSchemaIsAClearError)
{
	SKIP_WITHOUT_WRITER();
	const auto d = test::freshTmpDir("bims_ros2", "foreign");
	writeMcap(smallBag(3), d + "/brotli.mcap", "brotli");
	std::string e =
	    errorOf([&] { import(d + "/brotli.mcap", d + "/out.rawlog"); });
	EXPECT_TRUE(has(e, d + "/brotli.mcap") && has(e, "compression 'brotli'") &&
	            has(e, "the chunk at byte"))
	    << e;
	EXPECT_FALSE(fs::exists(d + "/out.rawlog"));

	BagSpec b = smallBag(3);
	b.spec["topics"][0]["schemaEncoding"] = "jsonschema";
	writeMcap(b, d + "/json.mcap");
	e = errorOf([&] { import(d + "/json.mcap", d + "/out.rawlog"); });
	EXPECT_TRUE(has(e, "channel") && has(e, "/camera/depth/image") &&
	            has(e, "'jsonschema', not ROS 2's ros2msg"))
	    << e;

	b = smallBag(3);
	b.spec["topics"][1]["messageEncoding"] = "json";
	writeMcap(b, d + "/enc.mcap");
	e = errorOf([&] { import(d + "/enc.mcap", d + "/out.rawlog"); });
	EXPECT_TRUE(has(e, "/camera/rgb/image_color") &&
	            has(e, "'json', not ROS 2's cdr"))
	    << e;

	writeText(d + "/not.mcap", "\x89MCAP1\r\nrest");
	e = errorOf([&] { import(d + "/not.mcap", d + "/out.rawlog"); });
	EXPECT_TRUE(has(e, "not.mcap: MCAP of another major version")) << e;
}

TEST(Ros2Import, AChunkWhoseCrcDoesNotMatchKeepsTheWholeFramesBeforeIt)
{
	SKIP_WITHOUT_WRITER();
	const auto d = test::freshTmpDir("bims_ros2", "crc");
	// a chunk of about one frame each; frame 3's colour marked
	const BagSpec b = smallBag(6, kTum, 3);
	writeMcap(b, d + "/whole.mcap", "", true, 4000);
	import(d + "/whole.mcap", d + "/whole.rawlog");
	std::string bytes = test::fileText(d + "/whole.mcap");
	const size_t at = bytes.find(std::string(64, '\xAB'));
	ASSERT_NE(at, std::string::npos);
	bytes[at + 10] = '\x01';
	writeText(d + "/bad.mcap", bytes);
	const std::string e =
	    errorOf([&] { import(d + "/bad.mcap", d + "/bad.rawlog"); });
	EXPECT_TRUE(has(e, d + "/bad.mcap") && has(e, "the chunk at byte") &&
	            has(e, "CRC") && has(e, "whole frames before it are in"))
	    << e;
	const auto kept = framesOf(d + "/bad.rawlog");
	EXPECT_GE(kept.size(), 2u);
	EXPECT_LT(kept.size(), 6u);
	expectFirstFrames(d + "/bad.rawlog", d + "/whole.rawlog");
}

TEST(Ros2Import, LengthsBeyondTheirRecordOrFileAreErrorsNotReads)
{
	SKIP_WITHOUT_WRITER();
	const auto d = test::freshTmpDir("bims_ros2", "lengths");
	writeMcap(smallBag(4), d + "/whole.mcap", "", true, 4000);
	const std::string whole = test::fileText(d + "/whole.mcap");
	// the first chunk: after the magic and the header record
	uint64_t headerLen = 0;
	std::memcpy(&headerLen, whole.data() + 9, 8);
	const size_t chunk = 8 + 9 + static_cast<size_t>(headerLen);
	ASSERT_EQ(whole[chunk], '\x06');
	auto spoilt = [&](size_t at, uint64_t v)
	{
		std::string b = whole;
		std::memcpy(&b[at], &v, 8);
		writeText(d + "/bad.mcap", b);
		return errorOf([&] { import(d + "/bad.mcap", d + "/bad.rawlog"); });
	};
	// the chunk record's length: beyond the file
	std::string e = spoilt(chunk + 1, uint64_t{1} << 62);
	EXPECT_TRUE(has(e, "bad.mcap: cut short or damaged: the chunk at byte " +
	                       std::to_string(chunk) + ": it declares " +
	                       std::to_string(uint64_t{1} << 62) + " bytes"))
	    << e;
	// its records' length (after 3 times 8, 4 and the empty compression's
	// 4 bytes): beyond the chunk
	e = spoilt(chunk + 9 + 32, 0xffffffffffull);
	EXPECT_TRUE(has(e, "its records declare 1099511627775 bytes")) << e;
	// its uncompressed size: more than 1 GiB is not allocated
	writeMcap(smallBag(4), d + "/zstd.mcap", "zstd", true, 4000);
	std::string z = test::fileText(d + "/zstd.mcap");
	const uint64_t huge = uint64_t{3} << 30;
	std::memcpy(&z[chunk + 9 + 16], &huge, 8);
	writeText(d + "/huge.mcap", z);
	e = errorOf([&] { import(d + "/huge.mcap", d + "/bad.rawlog"); });
	EXPECT_TRUE(
	    has(e, "declares 3221225472 uncompressed bytes: more than 1 GiB"))
	    << e;
}

TEST(Ros2Import, AMessageShorterThanItsTypeIsAnErrorNamingTopicAndMessage)
{
	SKIP_WITHOUT_WRITER();
	const auto d = test::freshTmpDir("bims_ros2", "short");
	BagSpec b = smallBag(5);
	// the 4th depth image cut after its header: its stamp reads, its
	// pixels do not (the whole frames before it are kept)
	int seen = 0;
	for (auto& m : b.spec["messages"])
		if (m["topic"] == 0 && ++seen == 4) m["truncate"] = 30;
	for (const std::string s : {"mcap", "db3"})
	{
		const std::string path = d + "/short." + s;
		if (s == "mcap")
			writeMcap(b, path, "zstd");
		else
			writeDb3(b, path);
		const std::string e =
		    errorOf([&] { import(path, d + "/" + s + ".rawlog"); });
		EXPECT_TRUE(has(e, path) && has(e, "topic /camera/depth/image") &&
		            has(e, "message #4 of it") &&
		            has(e, "shorter than its type") &&
		            has(e, "the 3 whole frames before it"))
		    << e;
		EXPECT_EQ(framesOf(d + "/" + s + ".rawlog").size(), 3u);
	}
	// cut inside its header: the first pass cannot read its stamp
	seen = 0;
	for (auto& m : b.spec["messages"])
		if (m["topic"] == 0 && ++seen == 2) m["truncate"] = 9;
	writeMcap(b, d + "/header.mcap");
	const std::string e =
	    errorOf([&] { import(d + "/header.mcap", d + "/h.rawlog"); });
	EXPECT_TRUE(has(e, "message #2 of it cannot be read") &&
	            has(e, "header's stamp"))
	    << e;
}

TEST(Ros2Import, ImagesWhoseStepOrSizeDisagreeWithTheirDataAreErrors)
{
	SKIP_WITHOUT_WRITER();
	const auto d = test::freshTmpDir("bims_ros2", "step");
	auto spoilt = [&](const std::function<void(json&)>& spoil)
	{
		BagSpec b = smallBag(4);
		int seen = 0;
		for (auto& m : b.spec["messages"])
			if (m["topic"] == 0 && ++seen == 3) spoil(m);
		writeMcap(b, d + "/b.mcap");
		return errorOf([&] { import(d + "/b.mcap", d + "/b.rawlog"); });
	};
	std::string e = spoilt([](json& m) { m["msg"]["step"] = kW * 4 + 8; });
	EXPECT_TRUE(has(e, "topic /camera/depth/image, message #3 of it") &&
	            has(e, "bytes of data for 24 rows of step 136"))
	    << e;
	e = spoilt([](json& m) { m["data"][1] = kW * kH * 4 - 100; });
	EXPECT_TRUE(has(e, "message #3 of it") && has(e, "corrupt")) << e;
	e = spoilt([](json& m) { m["msg"]["width"] = 40; });
	EXPECT_TRUE(has(e, "message #3 of it") &&
	            has(e, "is 40x24, the camera 32x24"))
	    << e;
	e = spoilt([](json& m) { m["msg"]["encoding"] = "rgba8"; });
	EXPECT_TRUE(has(e, "encoding 'rgba8' is not supported")) << e;
}

TEST(Ros2Import, ACutShortMcapGivesEveryWholeFrameBeforeTheCut)
{
	SKIP_WITHOUT_WRITER();
	const auto d = test::freshTmpDir("bims_ros2", "cut");
	for (const std::string c : {"", "zstd", "lz4"})
	{
		const std::string whole = d + "/whole" + c + ".mcap";
		writeMcap(smallBag(12), whole, c, true, 6000);
		import(whole, d + "/whole.rawlog");
		// without its summary: read whole, no error
		writeMcap(smallBag(12), d + "/nosummary.mcap", c, false, 6000);
		import(d + "/nosummary.mcap", d + "/nosummary.rawlog");
		EXPECT_TRUE(test::fileText(d + "/nosummary.rawlog") ==
		            test::fileText(d + "/whole.rawlog"))
		    << c;
		// messages outside chunks: the same rawlog
		writeMcap(smallBag(12), d + "/unchunked.mcap", c, true, 6000, false);
		import(d + "/unchunked.mcap", d + "/unchunked.rawlog");
		EXPECT_TRUE(test::fileText(d + "/unchunked.rawlog") ==
		            test::fileText(d + "/whole.rawlog"))
		    << c;
		const std::string bytes = test::fileText(whole);
		for (const double at : {0.5, 0.8})
		{
			const std::string cut = d + "/cut.mcap";
			writeText(cut, bytes.substr(0, size_t(at * double(bytes.size()))));
			const std::string e =
			    errorOf([&] { import(cut, d + "/cut.rawlog"); });
			EXPECT_TRUE(has(e, cut + ": cut short or damaged") &&
			            has(e, "byte") && has(e, "whole frames before it"))
			    << c << " at " << at << ": " << e;
			const auto kept = framesOf(d + "/cut.rawlog");
			EXPECT_GE(kept.size(), at < 0.6 ? 3u : 6u) << c << " at " << at;
			EXPECT_LT(kept.size(), 12u);
			expectFirstFrames(d + "/cut.rawlog", d + "/whole.rawlog");
		}
	}
}

TEST(Ros2Import, ADb3ThatIsNotSqliteOrLacksATableIsAClearError)
{
	const auto d = test::freshTmpDir("bims_ros2", "db3");
	writeText(d + "/not.db3", "this is no database, but long enough");
	std::string e = errorOf([&] { import(d + "/not.db3", d + "/out.rawlog"); });
	EXPECT_TRUE(has(e, d + "/not.db3") && has(e, "not a ROS 2 sqlite3 bag"))
	    << e;
	const std::string why = writerMissing();
	if (!why.empty()) GTEST_SKIP() << "ROS 2 writer: " << why;
	for (const std::string table : {"messages", "topics"})
	{
		writeDb3(smallBag(2), d + "/no_" + table + ".db3", table);
		e = errorOf(
		    [&] { import(d + "/no_" + table + ".db3", d + "/out.rawlog"); });
		EXPECT_TRUE(has(e, "no_" + table + ".db3") &&
		            has(e, "without the table '" + table + "'"))
		    << e;
	}
	// sqlite's header, then damage: an error, not a crash
	std::string bytes = test::fileText(d + "/no_topics.db3");
	writeDb3(smallBag(2), d + "/ok.db3");
	bytes = test::fileText(d + "/ok.db3");
	for (size_t k = 100; k < bytes.size(); k += 97) bytes[k] = '\x5a';
	writeText(d + "/damaged.db3", bytes);
	e = errorOf([&] { import(d + "/damaged.db3", d + "/out.rawlog"); });
	EXPECT_TRUE(has(e, "damaged.db3")) << e;
}

TEST(Ros2Import, CdrOfEitherByteOrderIsReadAlignedFromItsHeader)
{
	// a sensor_msgs/msg/MagneticField by hand, big-endian (CDR_BE): stamp,
	// frame_id "ab" (3 bytes with its NUL), padding to 8 from the header's
	// end, then the doubles
	auto be = [](std::string& s, const void* v, size_t n)
	{
		for (size_t k = n; k-- > 0;) s += static_cast<const char*>(v)[k];
	};
	std::string m("\x00\x00\x00\x00", 4);
	const int32_t sec = 7;
	const uint32_t nsec = 500000000, len = 3;
	be(m, &sec, 4);
	be(m, &nsec, 4);
	be(m, &len, 4);
	m += std::string("ab\0", 3);
	m += std::string(1, '\0');  // 15 bytes after the header: pad to 16
	for (const double v :
	     {1e-5, -2e-5, 3e-5, 0., 0., 0., 0., 0., 0., 0., 0., 0.})
		be(m, &v, 8);
	const auto* p = reinterpret_cast<const uint8_t*>(m.data());
	const bag::ImuSample s = bag::cdr::magneticField(p, m.size());
	EXPECT_EQ(s.t, 7.5);
	EXPECT_TRUE(s.hasMag);
	EXPECT_DOUBLE_EQ(s.m[0], 0.1);  // gauss
	EXPECT_DOUBLE_EQ(s.m[1], -0.2);
	// every byte short of it: an error saying so, never a read beyond
	for (size_t n = 0; n < m.size(); n++)
		EXPECT_FALSE(errorOf([&] { bag::cdr::magneticField(p, n); }).empty())
		    << n;
	EXPECT_TRUE(has(errorOf([&] { bag::cdr::magneticField(p, m.size() - 1); }),
	                "magnetic_field_covariance"));
	// XCDR2 and parameter lists are not read
	m[1] = '\x07';
	EXPECT_TRUE(has(errorOf([&] { bag::cdr::magneticField(p, m.size()); }),
	                "not CDR_BE or CDR_LE"));
}

// Issue 55, item 7: a header stamp with nanosec >= 1e9 (non-canonical)
// was refused as corrupt; ROS carries the whole seconds into sec.
TEST(Ros2Import, ANonCanonicalCdrStampIsNormalisedAsRosDoes)
{
	auto le = [](std::string& s, const void* v, size_t n)
	{ s.append(static_cast<const char*>(v), n); };
	std::string m("\x00\x01\x00\x00", 4);  // CDR_LE
	const int32_t sec = 999;
	const uint32_t nsec = 1500000000, len = 3;
	le(m, &sec, 4);
	le(m, &nsec, 4);
	le(m, &len, 4);
	m += std::string("ab\0", 3);
	m += std::string(1, '\0');
	for (const double v :
	     {1e-5, -2e-5, 3e-5, 0., 0., 0., 0., 0., 0., 0., 0., 0.})
		le(m, &v, 8);
	const auto* p = reinterpret_cast<const uint8_t*>(m.data());
	std::string e;
	bag::ImuSample s;
	try
	{
		s = bag::cdr::magneticField(p, m.size());
	}
	catch (const std::exception& x)
	{
		e = x.what();
	}
	EXPECT_EQ(e, "");
	EXPECT_EQ(s.t, 1000.5);  // not 999.15
	EXPECT_DOUBLE_EQ(s.m[0], 0.1);
}

/** \a mcap with its chunks' and data section's CRCs set to 0 ("not
 * computed"): a fuzzer's mutations of its chunks then reach the messages. */
std::string withoutCrcs(std::string mcap)
{
	auto u64 = [&](size_t at)
	{
		uint64_t v = 0;
		std::memcpy(&v, mcap.data() + at, 8);
		return v;
	};
	for (size_t pos = 8; pos + 9 <= mcap.size();)
	{
		const auto op = static_cast<uint8_t>(mcap[pos]);
		const size_t content = pos + 9;
		if (op == 0x06) std::memset(&mcap[content + 24], 0, 4);  // Chunk
		if (op == 0x0f)                                          // DataEnd
		{
			std::memset(&mcap[content], 0, 4);
			break;
		}
		pos = content + static_cast<size_t>(u64(pos + 1));
	}
	return mcap;
}

/** The fuzz targets' seeds (tests/fuzz/corpus/{mcap,db3,cdr}), written
 * when BIMS_WRITE_FUZZ_SEEDS names the corpus folder (docs/fuzz.md). */
TEST(Ros2Import, FuzzSeeds)
{
	const char* dir = std::getenv("BIMS_WRITE_FUZZ_SEEDS");
	if (!dir) GTEST_SKIP() << "BIMS_WRITE_FUZZ_SEEDS=DIR writes the seeds";
	SKIP_WITHOUT_WRITER();
	const std::string c = dir;
	for (const char* t : {"mcap", "db3", "cdr"})
		fs::create_directories(c + "/" + t);
	Names rs = kRealSense2;
	BagSpec tum = smallBag(3), realsense = smallBag(2, rs);
	writeMcap(tum, c + "/mcap/seed-tum.mcap");
	writeMcap(tum, c + "/mcap/seed-tum-zstd.mcap", "zstd");
	writeMcap(tum, c + "/mcap/seed-tum-lz4.mcap", "lz4", true, 8000);
	writeMcap(tum, c + "/mcap/seed-tum-nosummary.mcap", "", false, 8000);
	writeMcap(realsense, c + "/mcap/seed-realsense-zstd.mcap", "zstd");
	for (const char* f : {"seed-tum", "seed-realsense-zstd"})
		writeText(c + "/mcap/" + f + "-nocrc.mcap",
		          withoutCrcs(test::fileText(c + "/mcap/" + f + ".mcap")));
	writeDb3(tum, c + "/db3/seed-tum.db3");
	writeDb3(realsense, c + "/db3/seed-realsense.db3");
	// each message type once, as its CDR bytes after the target's type byte
	const std::string dump = c + "/cdr/dump";
	BagSpec b = realsense;
	b.add(b.topic("/c", "sensor_msgs/msg/CompressedImage"), "100.5",
	      {{"format", "16UC1; compressedDepth rvl"}}, std::string(40, '\1'));
	b.add(b.topic("/m", "sensor_msgs/msg/MagneticField"), "100.5",
	      {{"magnetic_field", {{"x", 1e-5}, {"y", 2e-5}, {"z", -3e-5}}},
	       {"magnetic_field_covariance", {0, 0, 0, 0, 0, 0, 0, 0, 0}}});
	b.spec["out"] = dump;
	b.spec["format"] = "dump";
	b.spec["blob"] = dump + ".blob";
	writeText(dump + ".blob", b.blob);
	writeText(dump + ".spec", b.spec.dump());
	ASSERT_EQ(test::runCommand("node '" + kWriter + "/write_bag.mjs' '" + dump +
	                           ".spec'")
	              .code,
	          0);
	const json index = json::parse(test::fileText(dump + ".json"));
	const std::string bytes = test::fileText(dump + ".bin");
	std::set<std::string> done;
	for (const auto& m : index["messages"])
	{
		const std::string type =
		    index["topics"][m["topic"].get<size_t>()]["type"];
		if (!done.insert(type).second) continue;
		const char kind = type == "sensor_msgs/msg/Image"             ? 0
		                  : type == "sensor_msgs/msg/CompressedImage" ? 1
		                  : type == "sensor_msgs/msg/CameraInfo"      ? 2
		                  : type == "sensor_msgs/msg/Imu"             ? 3
		                                                              : 4;
		const std::string name = type.substr(type.rfind('/') + 1);
		writeText(
		    c + "/cdr/seed-" + name + ".cdr",
		    std::string(1, kind) + bytes.substr(m["offset"].get<size_t>(),
		                                        m["length"].get<size_t>()));
	}
	for (const char* e : {".blob", ".spec", ".json", ".bin"})
		fs::remove(dump + e);
}

}  // namespace
