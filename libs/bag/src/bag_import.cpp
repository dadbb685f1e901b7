#include <bims/bag/bag_import.h>
#include <bims/common/input_file.h>
#include <bims/common/progress.h>
#include <bims/eval/association.h>
#include <bims/eval/rgbd_frame.h>
#include <bims/io/output_paths.h>
#include <bims/io/rawlog.h>
#include <bims/sensors/camera.h>
#include <cv_bridge/cv_bridge.h>
#include <mrpt/core/format.h>
#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>

#include <bims/bag/compressed_image.h>

#include "bag_file.h"
#include "db3_file.h"
#include "mcap_file.h"
#include "messages.h"
#include "ros2_metadata.h"
#include "rs_sdk.h"

namespace bims::bag
{
namespace fs = std::filesystem;

double stampSeconds(uint32_t sec, uint32_t nsec)
{
	// nanoseconds of a second or more carried into the seconds, as ROS's
	// normalizeSecNSec does (a stamp written without normalising)
	const uint64_t s = uint64_t{sec} + nsec / 1000000000u;
	char buf[40];
	std::snprintf(buf, sizeof(buf), "%llu.%09u",
	              static_cast<unsigned long long>(s), nsec % 1000000000u);
	return std::strtod(buf, nullptr);
}

namespace
{
/** The files read as one recording: ROS 1 bags, ROS 2 MCAP or sqlite3
 * files (a ROS 2 bag folder: the files its metadata.yaml lists). */
struct Bags
{
	std::vector<std::unique_ptr<MessageSource>> files;
	std::vector<std::string> paths;  ///< each file's, for the errors
	size_t size() const { return files.size(); }
	const std::unique_ptr<MessageSource>& operator[](size_t k) const
	{
		return files[k];
	}
};

/** The kind of file \a p is, by its first bytes (else its extension). */
enum class FileKind
{
	Ros1,
	Mcap,
	Db3
};
FileKind fileKind(const std::string& p)
{
	char head[16] = {};
	// a regular file only: a FIFO is refused, not waited on
	InputFile in(p, "bag");
	size_t got = 0;
	for (size_t n = 1; got < sizeof(head) && n > 0; got += n)
		n = in.read(head + got, sizeof(head) - got);
	if (got >= 5 && std::memcmp(head, "\x89MCAP", 5) == 0)
		return FileKind::Mcap;
	if (got == 16 && std::memcmp(head, "SQLite format 3", 16) == 0)
		return FileKind::Db3;
	if (got >= 8 && std::memcmp(head, "#ROSBAG ", 8) == 0)
		return FileKind::Ros1;
	const std::string ext = fs::path(p).extension().string();
	if (ext == ".mcap") return FileKind::Mcap;
	if (ext == ".db3") return FileKind::Db3;
	return FileKind::Ros1;
}

Bags openBags(const std::vector<std::string>& paths, size_t cacheBytes)
{
	Bags bags;
	for (const auto& p : paths)
	{
		std::error_code ec;
		if (!fs::exists(p, ec)) throw std::runtime_error(p + ": no such bag");
		std::vector<std::string> files = {p};
		if (fs::is_directory(p, ec))
		{
			if (!fs::exists(fs::path(p) / "metadata.yaml", ec))
				throw std::runtime_error(
				    p +
				    ": a folder without a metadata.yaml: not a ROS 2 bag "
				    "(a ROS 1 bag is a file)");
			files = ros2BagFiles(p);
		}
		for (const auto& f : files)
		{
			try
			{
				switch (fileKind(f))
				{
					case FileKind::Mcap:
						bags.files.push_back(
						    std::make_unique<McapFile>(f, cacheBytes));
						break;
					case FileKind::Db3:
						bags.files.push_back(std::make_unique<Db3File>(f));
						break;
					case FileKind::Ros1:
						bags.files.push_back(
						    std::make_unique<BagFile>(f, cacheBytes));
						break;
				}
			}
			catch (const std::exception& e)
			{
				throw std::runtime_error(f + ": " + e.what());
			}
			bags.paths.push_back(f);
		}
	}
	return bags;
}

std::string joined(const std::vector<std::string>& v)
{
	std::string s;
	for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
	return s;
}

/** Where a message is: "topic /x, message #n of it (stamp s)". */
std::string where(const std::string& topic, size_t n, double t = -1)
{
	std::string s =
	    "topic " + topic + ", message #" + std::to_string(n + 1) + " of it";
	if (t >= 0) s += mrpt::format(" (stamp %.6f)", t);
	return s;
}

const BagTopicInfo* findTopic(const std::vector<BagTopicInfo>& topics,
                              const std::string& name)
{
	for (const auto& t : topics)
		if (t.name == name) return &t;
	return nullptr;
}

/** image_transport's republished topic of a preset image topic: the
 * compressed plugin's "/compressed" (colour), compressed_depth's
 * "/compressedDepth" (depth). */
std::string transportTopic(const std::string& raw, bool depth)
{
	return raw + (depth ? "/compressedDepth" : "/compressed");
}

/** One vector of a time-sorted stream (the accelerometer's, the
 * magnetometer's) linearly interpolated at increasing stamps: the one rule
 * of both merges. */
class StreamInterpolator
{
 public:
	using Vector = double (ImuSample::*)[3];
	StreamInterpolator(const std::vector<ImuSample>& stream, Vector v)
	    : s_(stream), v_(v)
	{
	}
	/** The vector at \a t (not before the previous call's) into \a out;
	 * false outside the stream's time span. */
	bool at(double t, double out[3])
	{
		if (s_.empty() || t < s_.front().t || t > s_.back().t) return false;
		while (j_ + 1 < s_.size() && s_[j_ + 1].t < t) j_++;
		const ImuSample& a = s_[j_];
		const ImuSample& b = s_[std::min(j_ + 1, s_.size() - 1)];
		const double f =
		    b.t > a.t ? std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0) : 0.0;
		for (int k = 0; k < 3; k++)
			out[k] = (a.*v_)[k] + ((b.*v_)[k] - (a.*v_)[k]) * f;
		return true;
	}

 private:
	const std::vector<ImuSample>& s_;
	Vector v_;
	size_t j_ = 0;
};

/** The pixels of a raw image message as OpenCV sees them, in place in the
 * bag's bytes (as BGR when \a bgr: converted), after the checks a corrupt
 * or foreign message fails: encoding, size, step, data length. */
cv::Mat checkedImage(const ImageView& img,
                     const std::set<std::string>& encodings, const char* what,
                     int width, int height, bool bgr)
{
	if (!encodings.count(img.encoding))
	{
		std::vector<std::string> e(encodings.begin(), encodings.end());
		throw std::runtime_error(std::string(what) + " encoding '" +
		                         img.encoding + "' is not supported (" +
		                         joined(e) + ")");
	}
	if (static_cast<int>(img.width) != width ||
	    static_cast<int>(img.height) != height)
		throw std::runtime_error(mrpt::format("%s is %ux%u, the camera %dx%d",
		                                      what, img.width, img.height,
		                                      width, height));
	const size_t bpp = static_cast<size_t>(
	    sensor_msgs::image_encodings::numChannels(img.encoding) *
	    sensor_msgs::image_encodings::bitDepth(img.encoding) / 8);
	if (img.step < img.width * bpp ||
	    img.size < static_cast<size_t>(img.step) * img.height)
		throw std::runtime_error(mrpt::format(
		    "%s has %zu bytes of data for %u rows of step %u (%ux%u %s): "
		    "corrupt",
		    what, img.size, img.height, img.step, img.width, img.height,
		    img.encoding.c_str()));
	if (img.bigEndian && bpp > 1 && img.encoding != "rgb8" &&
	    img.encoding != "bgr8")
		throw std::runtime_error(std::string(what) +
		                         " is big-endian: not supported");
	const cv::Mat m(height, width, cv_bridge::getCvType(img.encoding),
	                const_cast<uint8_t*>(img.data), img.step);
	// 16- and 32-bit pixels where the bag has them may be misaligned for
	// their type (fuzz finding ub-misaligned-depth-pixels): then copied
	const size_t align = m.elemSize1();
	if (reinterpret_cast<uintptr_t>(m.data) % align != 0 || m.step % align != 0)
		return m.clone();
	if (!bgr || img.encoding == "bgr8") return m;
	cv::Mat out;
	cv::cvtColor(
	    m, out,
	    img.encoding == "rgb8" ? cv::COLOR_RGB2BGR : cv::COLOR_GRAY2BGR);
	return out;
}

}  // namespace

namespace
{
/** The topics on one line, for an error: "/a (type, N messages), ...". */
std::string topicList(const std::vector<BagTopicInfo>& topics)
{
	std::string s;
	for (const auto& t : topics)
		s += (s.empty() ? "" : ", ") + t.name + " (" + t.type + ", " +
		     std::to_string(t.messages) +
		     (t.messages == 1 ? " message)" : " messages)");
	return s.empty() ? "no topic" : s;
}
}  // namespace

std::string describeTopics(const std::vector<BagTopicInfo>& topics)
{
	std::string s;
	for (const auto& t : topics)
		s += mrpt::format("  %-45s %-28s %zu message%s\n", t.name.c_str(),
		                  t.type.c_str(), t.messages,
		                  t.messages == 1 ? "" : "s");
	return s.empty() ? "  (no topics)\n" : s;
}

BagLayout detectLayout(const std::vector<BagTopicInfo>& topics,
                       const std::string& bagNames)
{
	for (const auto l : {BagLayout::RealSense, BagLayout::Tum})
		for (const BagTopics& v : layoutVariants(l))
			if (findTopic(topics, v.depth) ||
			    findTopic(topics, transportTopic(v.depth, true)))
				return l;
	if (!rsSdkTopics(topics).depth.empty()) return BagLayout::RsSdk;
	throw std::runtime_error(
	    bagNames + ": no depth topic of a known layout (realsense: " +
	    layoutTopics(BagLayout::RealSense).depth +
	    ", tum: " + layoutTopics(BagLayout::Tum).depth +
	    ", rs-sdk: /device_N/sensor_N/Depth_N/image/data); name yours in "
	    "[import_bag] depth_topic (-c). The bag has: " +
	    topicList(topics));
}

std::vector<ImuSample> mergeAccelGyro(const std::vector<ImuSample>& accel,
                                      const std::vector<ImuSample>& gyro,
                                      size_t& leftOut)
{
	std::vector<ImuSample> out;
	leftOut = 0;
	StreamInterpolator a(accel, &ImuSample::a);
	for (const auto& g : gyro)
	{
		ImuSample s = g;
		if (!a.at(g.t, s.a))
		{
			leftOut++;
			continue;
		}
		s.hasGyro = true;
		s.hasAccel = true;
		out.push_back(s);
	}
	return out;
}

void attachMagnetometer(std::vector<ImuSample>& imu,
                        const std::vector<ImuSample>& mag)
{
	StreamInterpolator m(mag, &ImuSample::m);
	for (auto& s : imu)
		if (m.at(s.t, s.m)) s.hasMag = true;
}

namespace
{
constexpr const char* kImage = "sensor_msgs/Image";
constexpr const char* kCompressed = "sensor_msgs/CompressedImage";

/** The topic \a name, when the bag has it, must be of \a type (or of
 * \a other, when given): ROS 1's name or ROS 2's ("sensor_msgs/msg/Image"). */
void requireType(const std::vector<BagTopicInfo>& topics,
                 const std::string& name, const std::string& type,
                 const std::string& bagNames, const char* other = nullptr)
{
	const auto* t = findTopic(topics, name);
	if (t && baseType(t->type) != type &&
	    !(other && baseType(t->type) == other))
		throw std::runtime_error(bagNames + ": topic " + name + " is " +
		                         t->type + ", expected " + type +
		                         (other ? std::string(" or ") + other : ""));
}

/** The preset topics of \a layout the bag has: of the first of its
 * variants (ROS 1's names, realsense-ros 4.x's ROS 2 names) whose depth
 * topic, or its image_transport topic, is in \a topics. */
BagTopics presetFor(BagLayout layout, const std::vector<BagTopicInfo>& topics)
{
	if (layout == BagLayout::RsSdk) return rsSdkTopics(topics);
	for (const BagTopics& v : layoutVariants(layout))
		if (findTopic(topics, v.depth) ||
		    findTopic(topics, transportTopic(v.depth, true)))
			return v;
	return layoutTopics(layout);
}

/** rs-sdk: the depth alone in its own camera (colour_topic = none), or
 * its camera_info to register it to the colour camera. */
void sdkCameras(const BagImportParams& params,
                const std::vector<BagTopicInfo>& topics,
                const std::string& bagNames, BagTopics& t)
{
	if (t.colour.empty() && !t.depthCameraInfo.empty())
	{
		if (params.topics.cameraInfo.empty()) t.cameraInfo = t.depthCameraInfo;
		t.depthCameraInfo.clear();
	}
	if (!t.colour.empty() && t.depthCameraInfo.empty())
		throw std::runtime_error(
		    bagNames + ": the depth stream " + t.depth +
		    " has no camera_info (" + rsSdkTopics(topics).depthCameraInfo +
		    "): its depth cannot be registered to the colour camera "
		    "([import_bag] colour_topic = none imports the depth alone, "
		    "which needs it too). The bag has: " +
		    topicList(topics));
}

/** Every chosen topic has its message type (errors name the topic). */
void requireTypes(const std::vector<BagTopicInfo>& topics, const BagTopics& t,
                  const std::string& bagNames)
{
	requireType(topics, t.depth, kImage, bagNames, kCompressed);
	requireType(topics, t.colour, kImage, bagNames, kCompressed);
	requireType(topics, t.cameraInfo, "sensor_msgs/CameraInfo", bagNames);
	for (const auto* n : {&t.imu, &t.accel, &t.gyro})
		requireType(topics, *n, "sensor_msgs/Imu", bagNames);
	requireType(topics, t.mag, "sensor_msgs/MagneticField", bagNames);
	requireType(topics, t.depthCameraInfo, "sensor_msgs/CameraInfo", bagNames);
	requireType(topics, t.depthUnits, "std_msgs/Float32", bagNames);
	for (const auto* n : {&t.depthTf, &t.colourTf, &t.accelTf, &t.gyroTf})
		requireType(topics, *n, "geometry_msgs/Transform", bagNames);
}

/** The topics actually read: those of the layout the bag has, and every
 * topic the .ini names explicitly (missing: an error). */
BagTopics chooseTopics(const BagImportParams& params,
                       const std::vector<BagTopicInfo>& topics,
                       const std::string& bagNames, BagLayout& layout)
{
	layout = params.layout;
	if (layout == BagLayout::Auto)
		layout = params.topics.depth.empty() || params.topics.depth == "none"
		             ? detectLayout(topics, bagNames)
		             : BagLayout::Auto;
	BagTopics t = resolveTopics(params.topics, presetFor(layout, topics));
	auto missing = [&](const std::string& name, const char* what)
	{
		return std::runtime_error(
		    bagNames + ": no " + what + " topic " + name +
		    " (--layout, or [import_bag] of -c, names another). The bag "
		    "has: " +
		    topicList(topics));
	};
	if (t.depth.empty())
		throw std::runtime_error(
		    bagNames +
		    (layout == BagLayout::RsSdk
		         ? ": no depth stream of a RealSense SDK recording "
		           "(/device_N/sensor_N/Depth_N/image/data; "
		           "[import_bag] depth_topic names another). The bag has: " +
		               topicList(topics)
		         : ": no depth topic ([import_bag] depth_topic)"));
	// a preset image topic the bag lacks: its image_transport republished
	// topic when the bag has that (docs/import-bag.md)
	auto orTransport =
	    [&](std::string& name, const std::string& given, bool depth)
	{
		if (given.empty() && !name.empty() && !findTopic(topics, name) &&
		    findTopic(topics, transportTopic(name, depth)))
			name = transportTopic(name, depth);
	};
	orTransport(t.depth, params.topics.depth, true);
	orTransport(t.colour, params.topics.colour, false);
	if (!findTopic(topics, t.depth)) throw missing(t.depth, "depth");
	// a topic the .ini names must be there; a preset's may be absent
	auto keep =
	    [&](std::string& name, const std::string& given, const char* what)
	{
		if (name.empty() || findTopic(topics, name)) return;
		if (!given.empty()) throw missing(name, what);
		name.clear();
	};
	keep(t.colour, params.topics.colour, "colour");
	keep(t.cameraInfo, params.topics.cameraInfo, "CameraInfo");
	keep(t.imu, params.topics.imu, "IMU");
	keep(t.accel, params.topics.accel, "accelerometer");
	keep(t.gyro, params.topics.gyro, "gyro");
	keep(t.mag, params.topics.mag, "magnetometer");
	for (auto* n : {&t.depthCameraInfo, &t.depthUnits, &t.depthTf, &t.colourTf,
	                &t.accelTf, &t.gyroTf})
		keep(*n, "", "");
	if (!t.imu.empty()) t.accel.clear(), t.gyro.clear();  // one IMU
	if (layout == BagLayout::RsSdk) sdkCameras(params, topics, bagNames, t);
	const std::string presetInfo = presetFor(layout, topics).cameraInfo;
	if (t.cameraInfo.empty() && !params.camera)
		throw std::runtime_error(
		    bagNames + ": no CameraInfo topic" +
		    (presetInfo.empty() ? std::string() : " " + presetInfo) +
		    " for the intrinsics; name it in "
		    "[import_bag] camera_info_topic or give [camera] fx fy cx cy "
		    "width height (-c). The bag has: " +
		    topicList(topics));
	requireTypes(topics, t, bagNames);
	return t;
}

/** One message as the scan read it: where it is, and what the first pass
 * needs of it (an image's stamp; an Imu, MagneticField or CameraInfo
 * whole). */
struct Scanned
{
	size_t bag = 0;
	BagMessageRef ref;
	double t = -1;  ///< its header stamp [s] (images, Imu, MagneticField)
	ImuSample imu;  ///< an Imu's or a MagneticField's
	std::shared_ptr<const CameraInfoView> info;
	std::shared_ptr<const TransformView> tf;  ///< a Transform's
	/** A Float32's value; a raw image's float32 after its data
	 * (librealsense's depth units), else 0. */
	float value = 0;
	std::string error;  ///< why it cannot be read (said if it is used)
};

void extract(Scanned& s, const BagConnection& c, const uint8_t* p, size_t n)
{
	switch (messageKind(c.type))
	{
		case MessageKind::Image:
			s.t = headerStamp(c, p, n);
			if (c.wire == Wire::Ros1)
			{
				// the depth units librealsense's recorder appends (read
				// when the image is; its errors are said then)
				try
				{
					const ImageView v = readImage(c, p, n);
					if (v.tailSize == 4) std::memcpy(&s.value, v.tail, 4);
				}
				catch (const std::exception&)
				{
				}
			}
			break;
		case MessageKind::CompressedImage:
			s.t = headerStamp(c, p, n);
			break;
		case MessageKind::Float32:
			s.value = readFloat32(c, p, n);
			break;
		case MessageKind::Transform:
			s.tf =
			    std::make_shared<const TransformView>(readTransform(c, p, n));
			break;
		case MessageKind::CameraInfo:
			s.info =
			    std::make_shared<const CameraInfoView>(readCameraInfo(c, p, n));
			break;
		case MessageKind::Imu:
			s.imu = readImu(c, p, n);
			s.t = s.imu.t;
			break;
		case MessageKind::MagneticField:
			s.imu = readMagneticField(c, p, n);
			s.t = s.imu.t;
			break;
		case MessageKind::Other:
			break;
	}
}

/** What the scan of the bags read: every topic's messages in the bags'
 * time order (record times, as rosbag's View orders them). */
struct Scan
{
	struct Topic
	{
		std::string type;
		std::vector<Scanned> messages;
	};
	std::map<std::string, Topic> topics;
	/** A bag damaged where messages were ("BAG: cut short or damaged:
	 * ..."): the messages after it are lost. */
	std::string lost;
	size_t lostBag = 0;
	std::vector<std::string> notes;  ///< damage that loses nothing

	std::vector<BagTopicInfo> topicInfo() const
	{
		std::vector<BagTopicInfo> out;
		for (const auto& [name, t] : topics)
			out.push_back({name, t.type, t.messages.size()});
		return out;
	}
};

/** Reads every chunk of \a bag (the \a b th, \a path) once into \a scan:
 * each message's place, and what extract() reads of it when
 * \a extracting (else it is only counted). */
void scanBag(MessageSource& bag, size_t b, const std::string& path,
             bool extracting, Scan& scan)
{
	bag.scan(
	    [&](const BagMessageRef& ref, const uint8_t* data)
	    {
		    const BagConnection& c = bag.connections()[ref.connection];
		    Scan::Topic& topic = scan.topics[c.topic];
		    if (topic.type.empty()) topic.type = c.type;
		    Scanned s;
		    s.bag = b;
		    s.ref = ref;
		    try
		    {
			    if (extracting) extract(s, c, data, ref.size);
		    }
		    catch (const std::exception& e)
		    {
			    s.error = e.what();
		    }
		    topic.messages.push_back(std::move(s));
	    });
	if (bag.damage().empty()) return;
	if (!bag.damageLosesMessages())
		scan.notes.push_back(path + ": its index at its end is damaged (" +
		                     bag.damage() +
		                     "): not needed, every chunk was read");
	else if (scan.lost.empty())
	{
		scan.lost = path + ": cut short or damaged: " + bag.damage();
		scan.lostBag = b;
	}
}

/** scanBag of every bag, then each topic in the bags' time order. */
Scan scanBags(const Bags& bags)
{
	Scan scan;
	for (size_t b = 0; b < bags.size(); b++)
		scanBag(*bags[b], b, bags.paths[b], true, scan);
	for (auto& [name, t] : scan.topics)
		std::stable_sort(t.messages.begin(), t.messages.end(),
		                 [](const Scanned& x, const Scanned& y)
		                 { return x.ref.time < y.ref.time; });
	return scan;
}

/** An image message of the first pass: its stamp and where it is. */
struct ImageRef
{
	double t = 0;
	size_t n = 0;  ///< its index on its topic
	const std::string* topic = nullptr;
	const Scanned* msg = nullptr;
};

/** Whether two CameraInfo messages describe the same camera: image size
 * and K. */
bool sameCamera(const CameraInfoView& a, const CameraInfoView& b)
{
	return a.width == b.width && a.height == b.height &&
	       std::equal(a.K, a.K + 9, b.K);
}

/** Everything the first pass reads: the images' stamps, the camera, the
 * IMU streams. */
struct Index
{
	std::vector<ImageRef> depth, colour;
	std::shared_ptr<const CameraInfoView> info;
	size_t infoMessages = 0;
	std::vector<ImuSample> imu, accel, gyro, mag;
	/** rs-sdk: the depth stream's camera, the Depth Units option's values
	 * (in order), each tf topic's first message. */
	std::shared_ptr<const CameraInfoView> depthInfo;
	std::vector<float> units;
	std::map<std::string, std::shared_ptr<const TransformView>> tf;
};

/** Files the messages of one chosen topic into the index, in their order:
 * images and IMU samples whose stamp goes back are counted and left out;
 * of camera_info, Depth Units and tf the first is kept. */
struct TopicIndexer
{
	const BagTopics& t;
	const std::string& topic;
	Index& ix;
	BagImportSummary& sum;
	double last = -1;
	bool any = false;

	bool stampBack(double s)
	{
		if (any && s <= last) return true;
		any = true;
		last = s;
		return false;
	}
	void add(const Scanned& m, size_t n)
	{
		if (topic == t.depth || topic == t.colour)
		{
			if (stampBack(m.t))
			{
				sum.stampsBack++;
				return;
			}
			(topic == t.depth ? ix.depth : ix.colour)
			    .push_back({m.t, n, &topic, &m});
		}
		else if (topic == t.cameraInfo)
		{
			if (!ix.info)
				ix.info = m.info;
			else if (!sameCamera(*ix.info, *m.info))
			{
				// the first is used for every frame: said once
				if (sum.cameraInfoChanges++ == 0) sum.firstCameraInfoChange = n;
			}
			ix.infoMessages++;
		}
		else if (topic == t.depthCameraInfo)
		{
			if (!ix.depthInfo) ix.depthInfo = m.info;
		}
		else if (topic == t.depthUnits)
			ix.units.push_back(m.value);
		else if (m.tf)
		{
			if (!ix.tf.count(topic)) ix.tf[topic] = m.tf;
		}
		else if (stampBack(m.t))
			sum.imuStampsBack++;
		else
			addImu(m);
	}
	void addImu(const Scanned& m)
	{
		if (topic == t.mag)
		{
			ix.mag.push_back(m.imu);
			return;
		}
		ImuSample s = m.imu;
		if (topic == t.imu) ix.imu.push_back(s);
		if (topic == t.accel)
		{
			s.hasGyro = false;
			ix.accel.push_back(s);
		}
		if (topic == t.gyro)
		{
			s.hasAccel = false;
			ix.gyro.push_back(s);
		}
	}
};

/** The first pass: the chosen topics' messages in the bags' time order;
 * a message that cannot be read is an error naming it. */
Index readIndex(const Scan& scan, const Bags& bags, const BagTopics& t,
                const std::string& bagNames, BagImportSummary& sum)
{
	std::set<std::string> names;
	for (const auto* n : {&t.depth, &t.colour, &t.cameraInfo, &t.imu, &t.accel,
	                      &t.gyro, &t.mag, &t.depthCameraInfo, &t.depthUnits,
	                      &t.depthTf, &t.colourTf, &t.accelTf, &t.gyroTf})
		if (!n->empty()) names.insert(*n);
	Index ix;
	for (const std::string& topic : names)
	{
		const auto it = scan.topics.find(topic);
		if (it == scan.topics.end()) continue;
		const std::string& name = it->first;
		TopicIndexer indexer{t, name, ix, sum};
		for (size_t n = 0; n < it->second.messages.size(); n++)
		{
			const Scanned& m = it->second.messages[n];
			const std::string& type =
			    bags[m.bag]->connections()[m.ref.connection].type;
			if (m.error.empty() && type != it->second.type)
				throw std::runtime_error(bagNames + ": " + where(name, n) +
				                         ": a " + type + " on a topic of " +
				                         it->second.type);
			if (!m.error.empty())
				throw std::runtime_error(bagNames + ": " + where(name, n) +
				                         " cannot be read: " + m.error);
			indexer.add(m, n);
		}
	}
	sum.depthMessages = ix.depth.size();
	sum.colourMessages = ix.colour.size();
	if (ix.depth.empty())
		throw std::runtime_error(bagNames + ": topic " + t.depth +
		                         " has no image with a stamp after the one "
		                         "before it");
	return ix;
}

struct Frame
{
	double t = 0;
	const ImageRef* depth = nullptr;
	const ImageRef* colour = nullptr;
};

std::vector<Frame> pairFrames(const Index& ix, const BagImportParams& params,
                              const std::string& bagNames,
                              BagImportSummary& sum)
{
	std::vector<Frame> frames;
	if (ix.colour.empty())
		for (const auto& d : ix.depth) frames.push_back({d.t, &d, nullptr});
	else
	{
		std::vector<double> tc, td;
		for (const auto& c : ix.colour) tc.push_back(c.t);
		for (const auto& d : ix.depth) td.push_back(d.t);
		// sorted already (stamps that go back were left out)
		for (const auto& [i, j] :
		     eval::associateGreedy(tc, td, params.maxTimeGap))
		{
			Frame f;
			f.depth = &ix.depth[j];
			f.colour = &ix.colour[i];
			f.t = params.timestampFrom == eval::TimestampSource::Rgb
			          ? f.colour->t
			          : f.depth->t;
			frames.push_back(f);
		}
		if (frames.empty())
			throw std::runtime_error(
			    bagNames + ": no depth and colour images within " +
			    mrpt::format("%g", params.maxTimeGap) +
			    " s of each other ([import_bag] max_time_gap_s)");
		std::stable_sort(frames.begin(), frames.end(),
		                 [](const Frame& a, const Frame& b)
		                 { return a.t < b.t; });
	}
	sum.unpaired = ix.depth.size() - frames.size();
	return frames;
}

/** The pinhole camera of the CameraInfo \a ci of \a topic (its first
 * message), checked: an error naming the bag and topic when it has no
 * message or K is not a camera. */
mrpt::img::TCamera cameraOfInfo(const CameraInfoView* ci,
                                const std::string& topic,
                                const std::string& bagNames)
{
	if (!ci)
		throw std::runtime_error(bagNames + ": topic " + topic +
		                         " has no message");
	const double fx = ci->K[0], fy = ci->K[4], cx = ci->K[2], cy = ci->K[5];
	if (!(fx > 0 && fy > 0 && std::isfinite(fx) && std::isfinite(fy) &&
	      std::isfinite(cx) && std::isfinite(cy)) ||
	    ci->width == 0 || ci->height == 0)
		throw std::runtime_error(mrpt::format(
		    "%s: topic %s: CameraInfo K = [%g 0 %g; 0 %g %g] of a %ux%u "
		    "image is not a camera",
		    bagNames.c_str(), topic.c_str(), fx, cx, fy, cy, ci->width,
		    ci->height));
	sensors::checkIntrinsics({static_cast<int>(ci->width),
	                          static_cast<int>(ci->height), fx, fy, cx, cy},
	                         bagNames + ": topic " + topic +
	                             ": CameraInfo K of a " +
	                             std::to_string(ci->width) + "x" +
	                             std::to_string(ci->height) + " image");
	mrpt::img::TCamera c;
	c.ncols = ci->width;
	c.nrows = ci->height;
	c.setIntrinsicParamsFromValues(fx, fy, cx, cy);
	c.distortion = mrpt::img::DistortionModel::none;
	return c;
}

mrpt::img::TCamera cameraOf(const Index& ix, const BagImportParams& params,
                            const BagTopics& t, const std::string& bagNames,
                            BagImportSummary& sum)
{
	if (params.camera)
	{
		sum.cameraFrom = params.cameraFrom;
		sensors::checkIntrinsics(sensors::PinholeCamera::of(*params.camera),
		                         params.cameraFrom);
		return *params.camera;
	}
	const mrpt::img::TCamera c =
	    cameraOfInfo(ix.info.get(), t.cameraInfo, bagNames);
	sum.cameraFrom = "CameraInfo " + t.cameraInfo;
	if (sum.cameraInfoChanges > 0)
		sum.notes.push_back(mrpt::format(
		    "warning: topic %s: the CameraInfo changes mid-bag (%zu of its "
		    "%zu messages differ from the first, from message %zu on): the "
		    "first is used for every frame",
		    t.cameraInfo.c_str(), sum.cameraInfoChanges, ix.infoMessages,
		    sum.firstCameraInfoChange));
	for (const double k : ix.info->D) sum.distortionIgnored |= k != 0;
	if (sum.distortionIgnored) sum.distortionModel = ix.info->distortionModel;
	return c;
}

/** What an rs-sdk import needs beyond the other layouts': the depth's
 * units and, when it is registered to the colour camera, its own camera
 * and the extrinsics between them. */
struct RsSdkDepth
{
	bool on = false;          ///< the rs-sdk layout
	double units = 0;         ///< metres per unit of the depth images
	bool unitsGiven = false;  ///< by [import_bag] depth_units
	bool fromImages = false;  ///< the units the depth images carry
	std::optional<mrpt::img::TCamera> depthCamera;  ///< registration's
	RigidTransform depthToColour;
};

/** The reference stream of a tf topic: the N of ".../tf/N". */
std::string tfReference(const std::string& topic)
{
	return topic.substr(topic.rfind('/') + 1);
}

/** The transform of tf topic \a topic (its first message), checked. */
RigidTransform transformOf(const Index& ix, const std::string& topic,
                           const std::string& bagNames)
{
	const auto it = ix.tf.find(topic);
	if (it == ix.tf.end())
		throw std::runtime_error(bagNames + ": topic " + topic +
		                         " has no message");
	try
	{
		return rigidTransformOf(*it->second);
	}
	catch (const std::exception& e)
	{
		throw std::runtime_error(bagNames + ": " + where(topic, 0) +
		                         ": the extrinsics' " + e.what());
	}
}

/** The units of \a topic's messages, \a what: one value, a depth unit. */
double unitsOf(const std::vector<float>& v, const std::string& topic,
               const std::string& bagNames)
{
	for (size_t k = 0; k < v.size(); k++)
	{
		if (v[k] != v.front())
			throw std::runtime_error(
			    bagNames + ": " + where(topic, k) +
			    mrpt::format(": the depth units change during the recording "
			                 "(%g m, then %g m): not supported",
			                 v.front(), v[k]));
		if (!(v[k] >= 1e-6f && v[k] <= 0.1f))
			throw std::runtime_error(
			    bagNames + ": " + where(topic, k) +
			    mrpt::format(": depth units of %g m: not in [1e-6, 0.1] m",
			                 v[k]));
	}
	return v.front();
}

/** The rs-sdk layout's depth units: given, the Depth Units option's, or
 * the depth images' own (into \a sum). */
void sdkDepthUnits(const Index& ix, const BagTopics& t,
                   const BagImportParams& params,
                   const std::vector<Frame>& frames,
                   const std::string& bagNames, RsSdkDepth& d,
                   BagImportSummary& sum)
{
	if (params.depthUnits > 0)
	{
		d.units = params.depthUnits;
		d.unitsGiven = true;
		sum.depthUnitsFrom = "[import_bag] depth_units (--depth-units)";
	}
	else if (!ix.units.empty())
	{
		d.units = unitsOf(ix.units, t.depthUnits, bagNames);
		sum.depthUnitsFrom = "the Depth Units option " + t.depthUnits;
	}
	else if (frames.front().depth->msg->value != 0)
	{
		const ImageRef& first = *frames.front().depth;
		d.units = unitsOf({first.msg->value}, t.depth, bagNames);
		d.fromImages = true;
		sum.depthUnitsFrom = "the depth images' own depth_units " + t.depth;
	}
	else
		throw std::runtime_error(
		    bagNames +
		    ": no depth units: the recording has no Depth Units option "
		    "(/device_N/sensor_N/option/Depth Units/value, or Depth_Units) "
		    "and its depth images (topic " +
		    t.depth +
		    ") carry none; give them with --depth-units M ([import_bag] "
		    "depth_units), e.g. 0.001 (1 mm, a D400's default)");
	sum.depthUnits = d.units;
}

/** The depth stream's own camera and its extrinsics to the colour stream,
 * when the depth is to be registered to the colour camera. */
void sdkRegistration(const Index& ix, const BagTopics& t,
                     const std::string& bagNames, RsSdkDepth& d,
                     BagImportSummary& sum)
{
	d.depthCamera =
	    cameraOfInfo(ix.depthInfo.get(), t.depthCameraInfo, bagNames);
	if (t.depthTf.empty() || t.colourTf.empty())
		throw std::runtime_error(
		    bagNames + ": no extrinsics between the depth stream " + t.depth +
		    " and the colour stream " + t.colour + " (no tf/N topic of the " +
		    (t.depthTf.empty() ? "depth" : "colour") +
		    " stream): the depth cannot be registered to the colour "
		    "camera ([import_bag] colour_topic = none imports the depth "
		    "alone)");
	if (tfReference(t.depthTf) != tfReference(t.colourTf))
		throw std::runtime_error(
		    bagNames + ": the extrinsics " + t.depthTf + " and " + t.colourTf +
		    " are from different reference streams: not supported");
	d.depthToColour = compose(transformOf(ix, t.colourTf, bagNames),
	                          inverse(transformOf(ix, t.depthTf, bagNames)));
	sum.depthToColour = d.depthToColour;
}

/** The camera-to-IMU extrinsics from tf (the IMU's axes: the gyro's, the
 * merged samples being at its stamps, else the accelerometer's; the
 * camera: \a cameraTf), or a note saying why there are none. */
void sdkImuExtrinsics(const Index& ix, const BagTopics& t,
                      const std::string& cameraTf, const std::string& bagNames,
                      BagImportSummary& sum)
{
	const std::string& imuTf = t.gyro.empty() ? t.accelTf : t.gyroTf;
	const std::string& imuTopic = t.gyro.empty() ? t.accel : t.gyro;
	if (imuTopic.empty()) return;
	if (imuTf.empty() || cameraTf.empty())
	{
		sum.notes.push_back(
		    "warning: no extrinsics (tf/N) of the IMU stream " + imuTopic +
		    " or of the camera: no [calibration] R_IC written; give it "
		    "in the experiment's .ini");
		return;
	}
	if (tfReference(imuTf) != tfReference(cameraTf))
	{
		sum.notes.push_back("warning: the extrinsics " + imuTf + " and " +
		                    cameraTf +
		                    " are from different reference streams: no "
		                    "[calibration] R_IC written");
		return;
	}
	const RigidTransform imu = transformOf(ix, imuTf, bagNames);
	sum.cameraToImu =
	    compose(imu, inverse(transformOf(ix, cameraTf, bagNames)));
	sum.cameraToImuFrom = "tf " + imuTf + " and " + cameraTf;
	if (!t.gyro.empty() && !t.accel.empty() && !t.accelTf.empty() &&
	    tfReference(t.accelTf) == tfReference(imuTf))
	{
		const double deg = rotationDeg(
		    compose(transformOf(ix, t.accelTf, bagNames), inverse(imu)));
		if (deg > 0.5)
			sum.notes.push_back(mrpt::format(
			    "warning: the accelerometer's axes (%s) are %.2f deg "
			    "from the gyro's (%s): the merged samples are in the "
			    "gyro's axes, the accelerometer's not rotated",
			    t.accelTf.c_str(), deg, imuTf.c_str()));
	}
}

/** The rs-sdk layout's depth units, registration and extrinsics (into
 * \a sum, with notes): errors name the bag, topic and message. */
RsSdkDepth rsSdkDepth(const Index& ix, const BagTopics& t,
                      const BagImportParams& params,
                      const std::vector<Frame>& frames,
                      const std::string& bagNames, BagImportSummary& sum)
{
	RsSdkDepth d;
	d.on = true;
	sdkDepthUnits(ix, t, params, frames, bagNames, d, sum);
	// the depth registered to the colour camera with their extrinsics
	if (!t.depthCameraInfo.empty()) sdkRegistration(ix, t, bagNames, d, sum);
	// the frames' camera: the colour's when the depth is registered to it
	sdkImuExtrinsics(ix, t, d.depthCamera ? t.colourTf : t.depthTf, bagNames,
	                 sum);
	if (!t.accel.empty() && t.gyro.empty())
		sum.notes.push_back(
		    "warning: the accelerometer stream " + t.accel +
		    " has no gyro stream beside it (/device_N/sensor_N/Gyro_N/imu/"
		    "data): accelerometer-only samples (labelled " +
		    params.accelLabel + "), no IMU rotation between frames");
	return d;
}

/** OUT_gt/calibration.ini of an rs-sdk import: the frames' camera, the
 * IMU's rotation (when its extrinsics are known) and the labels, the
 * sections of an experiment .ini (bims-odom --calib reads it). */
std::string calibrationIni(const BagImportSummary& sum,
                           const BagImportParams& params,
                           const std::string& bagNames)
{
	const auto& c = sum.camera;
	std::string s =
	    "# Written by bims-import-bag from the RealSense SDK recording " +
	    bagNames +
	    ": the camera of the imported rawlog and the IMU's extrinsics.\n" +
	    mrpt::format(
	        "[camera]\nfx = %.9g\nfy = %.9g\ncx = %.9g\ncy = %.9g\nwidth = "
	        "%u\nheight = %u\n",
	        c.fx(), c.fy(), c.cx(), c.cy(), c.ncols, c.nrows);
	if (sum.depthToColour)
	{
		const auto& T = *sum.depthToColour;
		s += "# the depth was registered to this (the colour) camera with "
		     "the depth-to-colour extrinsics of the recording's tf, p_colour "
		     "= R p_depth + t:\n" +
		     mrpt::format(
		         "# R = %.9g %.9g %.9g  %.9g %.9g %.9g  %.9g %.9g "
		         "%.9g\n# t = %.9g %.9g %.9g m\n",
		         T.R[0], T.R[1], T.R[2], T.R[3], T.R[4], T.R[5], T.R[6], T.R[7],
		         T.R[8], T.t[0], T.t[1], T.t[2]);
	}
	if (sum.cameraToImu)
	{
		const auto& T = *sum.cameraToImu;
		s += "\n[calibration]\n# camera optical frame in the IMU frame, from "
		     "the recording's " +
		     sum.cameraToImuFrom + ": p_I = R_IC p_C + t\n" +
		     mrpt::format(
		         "R_IC = %.9g %.9g %.9g  %.9g %.9g %.9g  %.9g %.9g "
		         "%.9g\n# t = %.9g %.9g %.9g m (not used by bims)\n",
		         T.R[0], T.R[1], T.R[2], T.R[3], T.R[4], T.R[5], T.R[6], T.R[7],
		         T.R[8], T.t[0], T.t[1], T.t[2]) +
		     "# the SDK stamps its IMU and camera frames on one clock\n"
		     "time_offset_s = 0\n";
	}
	s += "\n[sensors]\nrgbd_label = " + params.rgbdLabel +
	     "\nimu_label = " + params.imuLabel + "\n";
	return s;
}

/** The IMU stream written: the Imu topic, or accel and gyro merged, with
 * the magnetometer attached. */
std::vector<ImuSample> imuStream(Index& ix, const BagTopics& t,
                                 BagImportSummary& sum)
{
	std::vector<ImuSample> out;
	if (!t.imu.empty())
	{
		out = std::move(ix.imu);
		sum.imuSource = "topic " + t.imu;
	}
	else if (!t.accel.empty() && !t.gyro.empty())
	{
		out = mergeAccelGyro(ix.accel, ix.gyro, sum.imuLeftOut);
		sum.imuSource = "topics " + t.accel + " and " + t.gyro +
		                " merged at the gyro's stamps";
	}
	else if (!t.accel.empty() || !t.gyro.empty())
	{
		out = std::move(t.accel.empty() ? ix.gyro : ix.accel);
		sum.imuSource = "topic " + (t.accel.empty() ? t.gyro : t.accel);
	}
	if (!t.mag.empty())
	{
		attachMagnetometer(out, ix.mag);
		sum.imuSource += " with the magnetometer of " + t.mag;
	}
	return out;
}

/** Makes n observations in order on a thread of its own, at most
 * kAhead before the one the caller takes; the first error ends it and is
 * handed over in its place. */
class AheadQueue
{
 public:
	struct Made
	{
		mrpt::obs::CObservation::Ptr obs;
		std::string error;  ///< not empty: making it failed (and the rest)
	};
	using Maker = std::function<mrpt::obs::CObservation::Ptr(size_t)>;

	AheadQueue(size_t n, Maker make)
	    : make_(std::move(make)), thread_([this, n] { loop(n); })
	{
	}
	~AheadQueue() { join(); }
	AheadQueue(const AheadQueue&) = delete;
	AheadQueue& operator=(const AheadQueue&) = delete;

	/** The next observation, waiting for it. */
	Made pop()
	{
		std::unique_lock<std::mutex> lock(m_);
		cv_.wait(lock, [&] { return !q_.empty(); });
		Made made = std::move(q_.front());
		q_.pop_front();
		cv_.notify_all();
		return made;
	}
	/** Stops making and waits for the thread. */
	void join()
	{
		{
			const std::lock_guard<std::mutex> lock(m_);
			stop_ = true;
		}
		cv_.notify_all();
		if (thread_.joinable()) thread_.join();
	}

 private:
	static constexpr size_t kAhead = 4;
	void loop(size_t n)
	{
		for (size_t k = 0; k < n; k++)
		{
			Made made;
			try
			{
				made.obs = make_(k);
			}
			catch (const std::exception& e)
			{
				made.error = e.what();
			}
			const bool failed = !made.error.empty();
			std::unique_lock<std::mutex> lock(m_);
			cv_.wait(lock, [&] { return q_.size() < kAhead || stop_; });
			if (stop_) return;
			q_.push_back(std::move(made));
			cv_.notify_all();
			if (failed) return;
		}
	}

	Maker make_;
	std::mutex m_;
	std::condition_variable cv_;
	std::deque<Made> q_;
	bool stop_ = false;
	std::thread thread_;  // last: started once the rest is built
};

}  // namespace

std::vector<BagTopicInfo> bagTopics(const std::vector<std::string>& bagPaths,
                                    std::vector<std::string>* damage)
{
	const Bags bags = openBags(bagPaths, BagImportOptions().chunkCacheBytes);
	std::map<std::string, BagTopicInfo> all;
	for (size_t b = 0; b < bags.size(); b++)
	{
		// the index when it is whole; otherwise the chunks, counted
		std::vector<BagTopicInfo> topics = bags[b]->indexTopics();
		if (topics.empty())
		{
			Scan scan;
			scanBag(*bags[b], b, bags.paths[b], false, scan);
			topics = scan.topicInfo();
			if (damage && !scan.lost.empty()) damage->push_back(scan.lost);
			if (damage)
				damage->insert(damage->end(), scan.notes.begin(),
				               scan.notes.end());
		}
		for (const auto& t : topics)
		{
			auto& a = all[t.name];
			a.name = t.name;
			if (a.type.empty()) a.type = t.type;
			a.messages += t.messages;
		}
	}
	std::vector<BagTopicInfo> out;
	for (auto& [name, t] : all) out.push_back(t);
	return out;
}

/** An observation of the import: an IMU sample or a frame. */
struct Item
{
	double t;
	int kind;  // 0 IMU, 1 frame
	size_t i;  ///< in the IMU samples or the frames
};

/** Frames and IMU samples in time order, IMU first at equal stamps; the
 * IMU within the frames' span (as bims-import-tum), the others counted in
 * \a sum.imuOutside. */
std::vector<Item> timeOrder(const std::vector<ImuSample>& imu,
                            const std::vector<Frame>& frames,
                            BagImportSummary& sum)
{
	const double t0 = frames.front().t, t1 = frames.back().t;
	std::vector<Item> items;
	for (size_t i = 0; i < imu.size(); i++)
		if (imu[i].t >= t0 && imu[i].t <= t1)
			items.push_back({imu[i].t, 0, i});
		else
			sum.imuOutside++;
	for (size_t i = 0; i < frames.size(); i++)
		items.push_back({frames[i].t, 1, i});
	std::stable_sort(items.begin(), items.end(),
	                 [](const Item& a, const Item& b)
	                 { return a.t < b.t || (a.t == b.t && a.kind < b.kind); });
	return items;
}

/** An SDK recording's depth image (Z16) with the units it carries (\a own,
 * 0 none) checked against the recording's, registered to the colour camera
 * \a cam when the depth has a camera of its own; \a units is set to the
 * result's metres per unit. */
cv::Mat sdkMetricDepth(const cv::Mat& depth, float own, const RsSdkDepth& sdk,
                       const std::string& unitsFrom,
                       const mrpt::img::TCamera& cam, double& units)
{
	if (depth.type() != CV_16UC1)
		throw std::runtime_error(
		    "the depth image is not 16-bit: not a RealSense SDK's Z16 depth");
	if (sdk.fromImages && own == 0)
		throw std::runtime_error("it carries no depth units, as the first did");
	if (!sdk.unitsGiven && own != 0 &&
	    std::abs(own - sdk.units) > 1e-6 * sdk.units)
		throw std::runtime_error(
		    mrpt::format("its own depth units %g m differ from %s's %g m", own,
		                 unitsFrom.c_str(), sdk.units));
	units = sdk.units;
	if (!sdk.depthCamera) return depth;
	units = 1.0;
	return registerDepth(depth, sdk.units, *sdk.depthCamera, cam,
	                     sdk.depthToColour);
}

namespace
{
/** What the import reads: the topics chosen, their index, the frames paired
 * (at most --max-frames) and the damage found after them (empty: none). */
struct ImportPlan
{
	BagLayout layout = BagLayout::Auto;
	BagTopics t;
	Index ix;
	std::vector<Frame> frames;
	std::string lost;
};

ImportPlan planImport(const Scan& scan, const Bags& bags,
                      const BagImportParams& params,
                      const BagImportOptions& options,
                      const std::string& bagNames, BagImportSummary& sum)
{
	ImportPlan plan;
	try
	{
		plan.t = chooseTopics(params, scan.topicInfo(), bagNames, plan.layout);
		sum.topics = plan.t;
		sum.layout = plan.layout;
		plan.ix = readIndex(scan, bags, plan.t, bagNames, sum);
		plan.frames = pairFrames(plan.ix, params, bagNames, sum);
	}
	catch (const std::exception& e)
	{
		// what was read before a damage may lack what it lost
		if (scan.lost.empty()) throw;
		throw std::runtime_error(scan.lost + "; before it: " + e.what());
	}
	// a bag damaged where messages were: every whole frame before the
	// damage is written, then the error says so (unless --max-frames is
	// reached before it)
	plan.lost = scan.lost;
	if (options.maxFrames > 0 && plan.frames.size() >= options.maxFrames)
	{
		if (!plan.lost.empty())
			sum.notes.push_back(plan.lost + " (after the frames imported)");
		plan.lost.clear();
		plan.frames.resize(options.maxFrames);
	}
	return plan;
}

/** The colour camera, checked against the CameraInfo topic's size; into
 * \a sum too. */
mrpt::img::TCamera checkedCamera(const ImportPlan& plan,
                                 const BagImportParams& params,
                                 const std::string& bagNames,
                                 BagImportSummary& sum)
{
	const mrpt::img::TCamera cam =
	    cameraOf(plan.ix, params, plan.t, bagNames, sum);
	const auto& info = plan.ix.info;
	if (info && (info->width != cam.ncols || info->height != cam.nrows))
		throw std::runtime_error(mrpt::format(
		    "%s: topic %s: CameraInfo of a %ux%u image, but %s says %ux%u",
		    bagNames.c_str(), plan.t.cameraInfo.c_str(), info->width,
		    info->height, sum.cameraFrom.c_str(), cam.ncols, cam.nrows));
	sum.camera = cam;
	sum.width = static_cast<int>(cam.ncols);
	sum.height = static_cast<int>(cam.nrows);
	return cam;
}

/** Each item of the import as its observation: an IMU sample, or a frame's
 * depth (in metres, the SDK's registered to the colour camera) with its
 * colour image. Run on the decoding thread, a few items ahead. */
class ItemDecoder
{
 public:
	ItemDecoder(const Bags& bags, const BagImportParams& params,
	            const RsSdkDepth& sdk, const std::vector<Frame>& frames,
	            const std::vector<ImuSample>& imu,
	            const mrpt::img::TCamera& cam, const BagImportSummary& sum,
	            const std::string& bagNames)
	    : bags_(bags),
	      params_(params),
	      sdk_(sdk),
	      frames_(frames),
	      imu_(imu),
	      cam_(cam),
	      sum_(sum),
	      bagNames_(bagNames),
	      W_(int(cam.ncols)),
	      H_(int(cam.nrows)),
	      // the depth image's size: the colour camera's, unless registered
	      // to it
	      DW_(sdk.depthCamera ? int(sdk.depthCamera->ncols) : W_),
	      DH_(sdk.depthCamera ? int(sdk.depthCamera->nrows) : H_)
	{
	}
	mrpt::obs::CObservation::Ptr operator()(const Item& it)
	{
		if (it.kind == 0)
		{
			const auto& s = imu_[it.i];
			return eval::imuObservation(
			    s.hasGyro ? params_.imuLabel : params_.accelLabel, s.t,
			    s.hasGyro ? s.w : nullptr, s.hasAccel ? s.a : nullptr,
			    s.hasMag ? s.m : nullptr);
		}
		const Frame& f = frames_[it.i];
		const ImageRef* current = f.depth;
		try
		{
			BagBytes heldDepth, heldColour;
			const cv::Mat depth =
			    image(*f.depth, true, depthEncoding, heldDepth);
			// REP 118: 16UC1 millimetres, 32FC1 metres; the SDK's in its
			// Depth Units
			double units = depth.type() == CV_32FC1 ? 1.0 : 0.001;
			cv::Mat metric = depth;
			if (sdk_.on)
				metric = sdkMetricDepth(depth, f.depth->msg->value, sdk_,
				                        sum_.depthUnitsFrom, cam_, units);
			auto o =
			    eval::depthObservation(metric, units, cam_, params_.rgbdLabel,
			                           f.t, params_.rangeUnits);
			if (f.colour)
			{
				current = f.colour;
				eval::attachColour(
				    *o, image(*f.colour, false, colourEncoding, heldColour));
			}
			return o;
		}
		catch (const std::exception& e)
		{
			throw std::runtime_error(
			    bagNames_ + ": " +
			    where(*current->topic, current->n, current->t) + ": " +
			    e.what());
		}
	}
	std::string depthEncoding, colourEncoding;  ///< the last decoded

 private:
	/** The image of a message, raw or compressed (its topic's type); \a held
	 * keeps a raw message's bytes while its pixels are used. */
	cv::Mat image(const ImageRef& ref, bool depth, std::string& encoding,
	              BagBytes& held) const
	{
		static const std::set<std::string> depthEncodings = {"16UC1", "32FC1",
		                                                     "mono16"};
		static const std::set<std::string> colourEncodings = {"rgb8", "bgr8",
		                                                      "mono8"};
		// the SDK's depth: Z16 as mono16 (or 16UC1), in its Depth Units
		static const std::set<std::string> sdkDepthEncodings = {"16UC1",
		                                                        "mono16"};
		const Scanned& m = *ref.msg;
		MessageSource& bag = *bags_[m.bag];
		const BagConnection& c = bag.connections()[m.ref.connection];
		held = bag.message(m.ref);
		if (messageKind(c.type) == MessageKind::CompressedImage)
		{
			const CompressedView ci = readCompressed(c, held.data, held.size);
			encoding = ci.format;
			return depth ? decodeCompressedDepth(ci.format, ci.data, ci.size,
			                                     DW_, DH_, params_.images)
			             : decodeCompressedColour(ci.format, ci.data, ci.size,
			                                      W_, H_, params_.images);
		}
		const ImageView r = readImage(c, held.data, held.size);
		encoding = r.encoding;
		return depth ? checkedImage(
		                   r, sdk_.on ? sdkDepthEncodings : depthEncodings,
		                   "the depth image", DW_, DH_, false)
		             : checkedImage(r, colourEncodings, "the colour image", W_,
		                            H_, true);
	}

	const Bags& bags_;
	const BagImportParams& params_;
	const RsSdkDepth& sdk_;
	const std::vector<Frame>& frames_;
	const std::vector<ImuSample>& imu_;
	const mrpt::img::TCamera& cam_;
	const BagImportSummary& sum_;
	const std::string& bagNames_;
	const int W_, H_, DW_, DH_;
};

/** Writes the items into \a outRawlog (with OUT_gt/calibration.ini for an
 * SDK recording), decoding a few ahead on a thread of their own; counts
 * them into \a sum. An error after whole frames keeps them and says so. */
void writeItems(const std::vector<Item>& items, ItemDecoder& decode,
                const std::vector<ImuSample>& imu, const std::string& lost,
                const std::string& outRawlog, bool sdk,
                const BagImportParams& params, const std::string& bagNames,
                const BagImportOptions& options, size_t frames,
                BagImportSummary& sum)
{
	AheadQueue ahead(items.size(), [&](size_t k) { return decode(items[k]); });
	PartialFile part(outRawlog);
	// rs-sdk: OUT_gt/calibration.ini, put in place with the rawlog
	std::optional<PartialDir> gt;
	if (sdk)
	{
		gt.emplace(groundTruthDirFor(outRawlog),
		           OutputFolderLayout{{"calibration.ini"}, {}});
		writeFileAtomically(gt->path() + "/calibration.ini",
		                    calibrationIni(sum, params, bagNames));
		sum.calibrationFile = gt->finalPath() + "/calibration.ini";
	}
	RawlogWriter w(part.path(), options.gzLevel);
	Progress progress;
	progress.total = frames;
	reportProgress(options.progress, progress);
	auto keepAndThrow = [&](const std::string& error)
	{
		if (sum.frames == 0) throw std::runtime_error(error);
		w.close();
		part.commit();
		if (gt) gt->commit();
		throw std::runtime_error(
		    error +
		    mrpt::format("; the %zu whole frames before it are in ",
		                 sum.frames) +
		    outRawlog);
	};
	for (size_t k = 0; k < items.size(); k++)
	{
		const auto next = ahead.pop();
		if (!next.error.empty()) keepAndThrow(next.error);
		w.write(*next.obs);
		if (items[k].kind == 1)
		{
			progress.done = ++sum.frames;
			reportProgress(options.progress, progress);
			continue;
		}
		const auto& s = imu[items[k].i];
		sum.imu++;
		sum.accelOnly += !s.hasGyro;
		sum.imuHasGyro |= s.hasGyro;
		sum.imuHasAccel |= s.hasAccel;
		sum.imuHasMag |= s.hasMag;
	}
	ahead.join();
	sum.depthEncoding = decode.depthEncoding;
	sum.colourEncoding = decode.colourEncoding;
	if (!lost.empty()) keepAndThrow(lost);
	w.close();
	part.commit();
	if (gt) gt->commit();
	progress.finished = true;
	reportProgress(options.progress, progress);
}
}  // namespace

BagImportSummary importBag(const std::vector<std::string>& bagPaths,
                           const std::string& outRawlog,
                           const BagImportParams& params,
                           const BagImportOptions& options)
{
	if (bagPaths.empty()) throw std::runtime_error("no bag to import");
	const Bags bags = openBags(bagPaths, options.chunkCacheBytes);
	const std::string bagNames = joined(bagPaths);
	const Scan scan = scanBags(bags);
	BagImportSummary sum;
	sum.notes = scan.notes;
	ImportPlan plan = planImport(scan, bags, params, options, bagNames, sum);
	const mrpt::img::TCamera cam = checkedCamera(plan, params, bagNames, sum);
	const RsSdkDepth sdk =
	    plan.layout == BagLayout::RsSdk
	        ? rsSdkDepth(plan.ix, plan.t, params, plan.frames, bagNames, sum)
	        : RsSdkDepth();
	const std::vector<ImuSample> imu = imuStream(plan.ix, plan.t, sum);
	const std::vector<Item> items = timeOrder(imu, plan.frames, sum);
	ItemDecoder decode(bags, params, sdk, plan.frames, imu, cam, sum, bagNames);
	writeItems(items, decode, imu, plan.lost, outRawlog, sdk.on, params,
	           bagNames, options, plan.frames.size(), sum);
	return sum;
}

}  // namespace bims::bag
