#include <bims/bag/cdr.h>
#include <bims/common/errors.h>
#include <bims/eval/rgbd_frame.h>
#include <bims/pipeline/run.h>
#include <bims/pipeline/stepper.h>
#include <bims/ros2/dds.h>
#include <bims/ros2/frame_queue.h>
#include <bims/ros2/node.h>
#include <mrpt/core/Clock.h>
#include <mrpt/math/CQuaternion.h>
#include <mrpt/obs/CObservationIMU.h>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>

#include "ros2_types.h"

namespace bims::ros2
{
namespace
{
using Clock = std::chrono::steady_clock;
using mrpt::obs::CObservation3DRangeScan;
using mrpt::obs::CObservationIMU;

/** A header's stamp as MRPT's time point, exactly (100 ns ticks). */
mrpt::Clock::time_point stampOf(const bag::cdr::HeaderTime& h)
{
	return mrpt::Clock::fromDouble(static_cast<double>(h.sec)) +
	       std::chrono::duration_cast<mrpt::Clock::duration>(
	           std::chrono::nanoseconds(h.nsec));
}

/** The frame_id of a message starting with a std_msgs/Header (the decoder
 * checked the message already). */
std::string frameIdOf(const std::vector<uint8_t>& b)
{
	// 4 header + 8 stamp, then the string's length and bytes
	if (b.size() < 16) return {};
	uint32_t n;
	std::memcpy(&n, b.data() + 12, 4);
	if (b[1] == 0x00) n = __builtin_bswap32(n);  // CDR_BE
	if (n == 0 || n > b.size() - 16) return {};
	return std::string(reinterpret_cast<const char*>(b.data() + 16), n - 1);
}

struct Header
{
	bag::cdr::HeaderTime stamp;
	std::string frameId;
};

/** An item of the processing queue, in arrival order. */
struct Item
{
	CObservationIMU::Ptr imu;
	CObservation3DRangeScan::Ptr scan;
	Header header;  // of the scan
};

using FrameQueue = DropOldestQueue<Item>;

/** Checks an image's declared size against its data; "" when it agrees. */
std::string imageProblem(const bag::ImageView& v, int bytesPerPixel)
{
	using std::to_string;
	const std::string size = to_string(v.width) + "x" + to_string(v.height);
	if (v.width == 0 || v.height == 0 || v.width > 16384 || v.height > 16384)
		return "its size " + size + " is not an image's";
	if (uint64_t(v.step) < uint64_t(v.width) * bytesPerPixel ||
	    uint64_t(v.step) * v.height != v.size)
		return "its step " + to_string(v.step) + " and size " + size + " (" +
		       to_string(bytesPerPixel) + " bytes a pixel) disagree with its " +
		       to_string(v.size) + " bytes of data";
	if (v.bigEndian && bytesPerPixel > 1) return "it is big-endian";
	return {};
}

int bytesPerPixelOf(const std::string& enc)
{
	if (enc == "16UC1" || enc == "mono16") return 2;
	if (enc == "32FC1") return 4;
	if (enc == "rgb8" || enc == "bgr8") return 3;
	if (enc == "mono8" || enc == "8UC1") return 1;
	return 0;
}

class Node
{
 public:
	Node(const pipeline::ExperimentConfig& cfg, const Ros2Params& p,
	     const NodeOptions& opt)
	    : cfg_(cfg), p_(p), opt_(opt), queue_(size_t(p.queueFrames))
	{
		if (!opt_.log) opt_.log = [](const std::string&) {};
	}

	NodeStats run();

 private:
	void warnOnce(const std::string& key, const std::string& text)
	{
		if (warned_.insert(key).second) opt_.log(opt_.program + ": " + text);
	}
	void receive();
	void checkPeers();
	void onDepth(const std::vector<uint8_t>& b);
	void onColour(const std::vector<uint8_t>& b);
	void onInfo(const std::vector<uint8_t>& b);
	void onImu(const std::vector<uint8_t>& b);
	void onMag(const std::vector<uint8_t>& b);
	void releaseFrames(bool all);
	void releaseImu(bool all);
	void process();
	void publish(const source::SourceFrame& f, const pipeline::FrameResult& r);
	bool stopped() const
	{
		return (opt_.stop && opt_.stop->load()) || done_.load();
	}

	const pipeline::ExperimentConfig& cfg_;
	Ros2Params p_;
	NodeOptions opt_;
	FrameQueue queue_;
	NodeStats st_;
	std::atomic<bool> done_{false};
	std::set<std::string> warned_;

	DdsEntity participant_;
	dds_entity_t rDepth_ = 0, rColour_ = 0, rInfo_ = 0, rImu_ = 0, rMag_ = 0,
	             rPubs_ = 0;
	dds_entity_t wMask_ = 0, wOdom_ = 0, wPoints_ = 0;
	Clock::time_point lastPeerCheck_{};

	// receiving thread's state
	std::optional<mrpt::img::TCamera> camera_;
	struct Colour
	{
		mrpt::Clock::time_point t;
		cv::Mat bgr;
	};
	std::deque<Colour> colours_;
	struct PendingDepth
	{
		Item item;
		cv::Mat depth;  // 16UC1 or 32FC1
		double metresPerUnit;
		Clock::time_point arrived;
	};
	std::deque<PendingDepth> depths_;
	struct PendingImu
	{
		CObservationIMU::Ptr obs;
		Clock::time_point arrived;
	};
	std::deque<PendingImu> imus_;
	std::map<mrpt::Clock::time_point, bag::ImuSample> mags_;

	// processing thread's state: the headers of the frames in flight
	std::map<mrpt::Clock::time_point, Header> headers_;
};

void Node::checkPeers()
{
	// another type on a topic we read: DDS does not match it, so nothing
	// arrives; say so, naming the topic and both types
	void* samples[16] = {};
	dds_sample_info_t infos[16];
	const int n = dds_take(rPubs_, samples, infos, 16, 16);
	const std::pair<std::string, const char*> ours[] = {
	    {p_.depthTopic, sensor_msgs_msg_dds__Image__desc.m_typename},
	    {p_.colourTopic, sensor_msgs_msg_dds__Image__desc.m_typename},
	    {p_.cameraInfoTopic, sensor_msgs_msg_dds__CameraInfo__desc.m_typename},
	    {p_.imuTopic, sensor_msgs_msg_dds__Imu__desc.m_typename},
	    {p_.magTopic, sensor_msgs_msg_dds__MagneticField__desc.m_typename}};
	for (int i = 0; i < n; i++)
	{
		if (!infos[i].valid_data) continue;
		const auto* e =
		    static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
		for (const auto& [topic, type] : ours)
			if (topicGiven(topic) && e->topic_name && e->type_name &&
			    ddsTopicName(topic) == e->topic_name &&
			    std::strcmp(type, e->type_name) != 0)
				warnOnce(topic + "|" + e->type_name,
				         "topic " + topic + ": a peer publishes type " +
				             e->type_name + ", not " + type +
				             ": its messages are not read");
	}
	if (n > 0) dds_return_loan(rPubs_, samples, n);
}

void Node::onInfo(const std::vector<uint8_t>& b)
{
	const auto v = bag::cdr::cameraInfo(b.data(), b.size());
	if (v.width == 0 || v.height == 0 || v.K[0] <= 0 || v.K[4] <= 0)
		throw std::runtime_error("its size or focal length is not a camera's");
	mrpt::img::TCamera c;
	c.ncols = v.width;
	c.nrows = v.height;
	c.fx(v.K[0]);
	c.fy(v.K[4]);
	c.cx(v.K[2]);
	c.cy(v.K[5]);
	for (size_t k = 0; k < std::min<size_t>(v.D.size(), 5); k++)
		c.dist[k] = v.D[k];
	camera_ = c;
}

void Node::onColour(const std::vector<uint8_t>& b)
{
	const auto v = bag::cdr::image(b.data(), b.size());
	const int bpp = bytesPerPixelOf(v.encoding);
	if (bpp != 3 && bpp != 1)
		throw std::runtime_error("its encoding '" + v.encoding +
		                         "' is not rgb8, bgr8 nor mono8");
	if (const auto e = imageProblem(v, bpp); !e.empty())
		throw std::runtime_error(e);
	const cv::Mat in(int(v.height), int(v.width), bpp == 3 ? CV_8UC3 : CV_8UC1,
	                 const_cast<uint8_t*>(v.data), v.step);
	Colour c;
	c.t = stampOf(bag::cdr::headerTime(b.data(), b.size()));
	if (v.encoding == "rgb8")
		cv::cvtColor(in, c.bgr, cv::COLOR_RGB2BGR);
	else if (bpp == 1)
		cv::cvtColor(in, c.bgr, cv::COLOR_GRAY2BGR);
	else
		c.bgr = in.clone();
	colours_.push_back(std::move(c));
	while (colours_.size() > 30) colours_.pop_front();
}

void Node::onDepth(const std::vector<uint8_t>& b)
{
	st_.depthReceived++;
	const auto v = bag::cdr::image(b.data(), b.size());
	const int bpp = bytesPerPixelOf(v.encoding);
	if (bpp != 2 && bpp != 4)
		throw std::runtime_error("its encoding '" + v.encoding +
		                         "' is not 16UC1 nor 32FC1");
	if (const auto e = imageProblem(v, bpp); !e.empty())
		throw std::runtime_error(e);
	PendingDepth d;
	d.item.header = {bag::cdr::headerTime(b.data(), b.size()), frameIdOf(b)};
	const cv::Mat in(int(v.height), int(v.width),
	                 bpp == 2 ? CV_16UC1 : CV_32FC1,
	                 const_cast<uint8_t*>(v.data), v.step);
	d.depth = in.clone();
	d.metresPerUnit = bpp == 2 ? p_.depthUnits : 1.0;
	d.arrived = Clock::now();
	depths_.push_back(std::move(d));
}

void Node::onImu(const std::vector<uint8_t>& b)
{
	const auto s = bag::cdr::imu(b.data(), b.size());
	const auto t = stampOf(bag::cdr::headerTime(b.data(), b.size()));
	auto o = eval::imuObservation(
	    cfg_.ego.sensors.imu_label, mrpt::Clock::toDouble(t),
	    s.hasGyro ? s.w : nullptr, s.hasAccel ? s.a : nullptr, nullptr);
	o->timestamp = t;  // exactly the header's
	if (s.hasOrientation)
	{
		using namespace mrpt::obs;
		o->set(IMU_ORI_QUAT_X, s.q[0]);
		o->set(IMU_ORI_QUAT_Y, s.q[1]);
		o->set(IMU_ORI_QUAT_Z, s.q[2]);
		o->set(IMU_ORI_QUAT_W, s.q[3]);
	}
	st_.imuReceived++;
	imus_.push_back({o, Clock::now()});
}

void Node::onMag(const std::vector<uint8_t>& b)
{
	const auto s = bag::cdr::magneticField(b.data(), b.size());
	mags_[stampOf(bag::cdr::headerTime(b.data(), b.size()))] = s;
	while (mags_.size() > 200) mags_.erase(mags_.begin());
}

void Node::releaseImu(bool all)
{
	// with a magnetometer topic, a sample waits (up to 0.2 s) for the
	// magnetic field of its stamp
	const bool mag = topicGiven(p_.magTopic);
	while (!imus_.empty())
	{
		auto& i = imus_.front();
		const auto m = mags_.find(i.obs->timestamp);
		if (mag && m == mags_.end() && !all &&
		    Clock::now() - i.arrived < std::chrono::milliseconds(200))
			break;
		if (mag && m != mags_.end())
		{
			using namespace mrpt::obs;
			i.obs->set(IMU_MAG_X, m->second.m[0]);
			i.obs->set(IMU_MAG_Y, m->second.m[1]);
			i.obs->set(IMU_MAG_Z, m->second.m[2]);
			mags_.erase(mags_.begin(), std::next(m));
		}
		Item it;
		it.imu = i.obs;
		queue_.push(std::move(it));
		imus_.pop_front();
	}
}

void Node::releaseFrames(bool all)
{
	const bool colour = topicGiven(p_.colourTopic);
	while (!depths_.empty())
	{
		auto& d = depths_.front();
		const auto t = stampOf(d.item.header.stamp);
		const Colour* match = nullptr;
		if (colour)
			for (const auto& c : colours_)
				if (std::abs(mrpt::Clock::toDouble(c.t) -
				             mrpt::Clock::toDouble(t)) <= p_.maxTimeGap)
				{
					match = &c;
					break;
				}
		const bool waited = Clock::now() - d.arrived >
		                    std::chrono::duration<double>(p_.colourWait);
		if (colour && !match && !waited && !all) break;
		if (colour && !match)
			warnOnce("nocolour", "topic " + p_.colourTopic +
			                         ": no colour image within " +
			                         std::to_string(p_.maxTimeGap) +
			                         " s of a depth image: it runs without");
		// the IMU samples received before it go first
		releaseImu(all);
		if (!camera_)
		{
			warnOnce("noinfo", "topic " + p_.cameraInfoTopic +
			                       ": no camera_info received yet: depth "
			                       "images are not used until one comes");
			st_.framesRejected++;
			depths_.pop_front();
			continue;
		}
		if (d.depth.cols != int(camera_->ncols) ||
		    d.depth.rows != int(camera_->nrows))
		{
			warnOnce("infosize",
			         "topic " + p_.depthTopic + ": its images are " +
			             std::to_string(d.depth.cols) + "x" +
			             std::to_string(d.depth.rows) + ", topic " +
			             p_.cameraInfoTopic + " says " +
			             std::to_string(camera_->ncols) + "x" +
			             std::to_string(camera_->nrows) + ": not used");
			st_.framesRejected++;
			depths_.pop_front();
			continue;
		}
		auto scan = eval::depthObservation(
		    d.depth, d.metresPerUnit, *camera_, cfg_.ego.sensors.rgbd_label,
		    mrpt::Clock::toDouble(t), p_.rangeUnits);
		scan->timestamp = t;  // exactly the header's
		if (match && match->bgr.cols == d.depth.cols &&
		    match->bgr.rows == d.depth.rows)
			eval::attachColour(*scan, match->bgr);
		else if (match)
			warnOnce("coloursize", "topic " + p_.colourTopic +
			                           ": its images are not the depth's "
			                           "size: frames run without colour");
		d.item.scan = scan;
		st_.framesQueued++;
		const size_t dropped = queue_.push(std::move(d.item));
		if (dropped > 0)
		{
			if (st_.framesDropped == 0)
				opt_.log(opt_.program +
				         ": frames arrive faster than they are processed: "
				         "the oldest waiting are dropped (counted)");
			st_.framesDropped += dropped;
		}
		depths_.pop_front();
	}
	if (all || depths_.empty()) releaseImu(all);
}

void Node::receive()
{
	const std::pair<dds_entity_t*, void (Node::*)(const std::vector<uint8_t>&)>
	    readers[] = {{&rInfo_, &Node::onInfo},
	                 {&rMag_, &Node::onMag},
	                 {&rImu_, &Node::onImu},
	                 {&rColour_, &Node::onColour},
	                 {&rDepth_, &Node::onDepth}};
	const std::string* topics[] = {&p_.cameraInfoTopic, &p_.magTopic,
	                               &p_.imuTopic, &p_.colourTopic,
	                               &p_.depthTopic};
	while (!stopped())
	{
		bool any = false;
		for (size_t k = 0; k < 5; k++)
		{
			if (*readers[k].first == 0) continue;
			for (auto& s : takeCdr(*readers[k].first))
			{
				any = true;
				if (!s.valid) continue;
				try
				{
					(this->*readers[k].second)(s.bytes);
				}
				catch (const std::exception& e)
				{
					st_.messagesRejected++;
					warnOnce(*topics[k] + "|" + e.what(),
					         "topic " + *topics[k] +
					             ": a message not used: " + e.what());
				}
			}
		}
		releaseFrames(false);
		if (Clock::now() - lastPeerCheck_ > std::chrono::milliseconds(200))
		{
			checkPeers();
			lastPeerCheck_ = Clock::now();
		}
		if (!any) std::this_thread::sleep_for(std::chrono::milliseconds(2));
	}
	releaseFrames(true);
	queue_.close();
}

template <typename T>
dds_sequence_uint8 bytesOf(T* data, size_t n)
{
	dds_sequence_uint8 s{};
	s._maximum = s._length = static_cast<uint32_t>(n);
	s._buffer = reinterpret_cast<uint8_t*>(data);
	s._release = false;
	return s;
}

void Node::publish(const source::SourceFrame& f, const pipeline::FrameResult& r)
{
	const auto h = headers_.find(f.scan->timestamp);
	Header hd;
	if (h != headers_.end())
	{
		hd = h->second;
		headers_.erase(headers_.begin(), std::next(h));
	}
	builtin_interfaces_msg_dds__Time_ stamp{static_cast<int32_t>(hd.stamp.sec),
	                                        hd.stamp.nsec};
	std::string frameId = hd.frameId, world = p_.worldFrame;

	// the mask: the depth image's header, mono8, 255 = moving
	cv::Mat mask = r.mask;
	if (mask.empty())
		mask = cv::Mat::zeros(int(f.scan->rangeImage.rows()),
		                      int(f.scan->rangeImage.cols()), CV_8UC1);
	if (!mask.isContinuous()) mask = mask.clone();
	sensor_msgs_msg_dds__Image_ img{};
	img.header.stamp = stamp;
	img.header.frame_id = frameId.data();
	img.height = uint32_t(mask.rows);
	img.width = uint32_t(mask.cols);
	char mono8[] = "mono8";
	img.encoding = mono8;
	img.step = uint32_t(mask.cols);
	img.data = bytesOf(mask.data, mask.total());
	dds_write(wMask_, &img);

	// the odometry: T_WC, the camera's optical frame in the world
	nav_msgs_msg_dds__Odometry_ od{};
	od.header.stamp = stamp;
	od.header.frame_id = world.data();
	od.child_frame_id = frameId.data();
	mrpt::math::CQuaternionDouble q;
	r.T_WC.getAsQuaternion(q);
	od.pose.pose.position = {r.T_WC.x(), r.T_WC.y(), r.T_WC.z()};
	od.pose.pose.orientation = {q.x(), q.y(), q.z(), q.r()};
	dds_write(wOdom_, &od);

	// the moving voxels' centres, float32 x y z in the world
	std::vector<float> xyz;
	xyz.reserve(r.movingVoxelCentres.size() * 3);
	for (const auto& c : r.movingVoxelCentres)
		for (double x : {c.x, c.y, c.z}) xyz.push_back(static_cast<float>(x));
	char nx[] = "x", ny[] = "y", nz[] = "z";
	sensor_msgs_msg_dds__PointField_ fields[3] = {
	    {nx, 0, 7, 1}, {ny, 4, 7, 1}, {nz, 8, 7, 1}};  // 7: FLOAT32
	sensor_msgs_msg_dds__PointCloud2_ pc{};
	pc.header.stamp = stamp;
	pc.header.frame_id = world.data();
	pc.height = 1;
	pc.width = uint32_t(r.movingVoxelCentres.size());
	pc.fields._maximum = pc.fields._length = 3;
	pc.fields._buffer = fields;
	pc.fields._release = false;
	pc.is_bigendian = false;
	pc.point_step = 12;
	pc.row_step = 12 * pc.width;
	pc.data = bytesOf(xyz.data(), xyz.size() * sizeof(float));
	pc.is_dense = true;
	dds_write(wPoints_, &pc);
}

void Node::process()
{
	pipeline::RunOptions ro;
	ro.outDir = opt_.outDir;
	ro.laterFiles = opt_.laterFiles;
	pipeline::RunRecorder rec(cfg_, ro);
	pipeline::LiveSegmentation seg(cfg_, opt_.program, "ROS 2 topics",
	                               !opt_.outDir.empty());
	const auto maxed = [&]
	{ return opt_.maxFrames > 0 && st_.framesProcessed >= opt_.maxFrames; };
	const auto onFrame =
	    [&](const source::SourceFrame& f, const pipeline::FrameResult& r)
	{
		publish(f, r);  // first: the recorder then owns the scan
		rec.frame(f, r, seg.lastCpuMs());
		st_.framesProcessed++;
		if (maxed()) done_ = true;
	};
	std::string error;
	try
	{
		while (auto it = queue_.pop())
		{
			if (maxed()) continue;  // drain
			if (it->scan)
			{
				headers_[it->scan->timestamp] = it->header;
				seg.push(it->scan, onFrame);
			}
			else
				seg.push(it->imu, onFrame);
		}
		if (!maxed())
		{
			seg.finish(onFrame);
			rec.trailing(seg.takeTrailing());
		}
	}
	catch (const std::exception& e)
	{
		error = withoutBacktrace(e.what());
		done_ = true;  // the receiver stops
	}
	st_.run = rec.finish(seg.pipeline(), seg.stats(), error, false);
}

NodeStats Node::run()
{
	participant_ = DdsEntity(ddsCheck(
	    dds_create_participant(dds_domainid_t(p_.domainId), nullptr, nullptr),
	    "DDS participant (domain " + std::to_string(p_.domainId) + ")"));
	const dds_entity_t pp = participant_.get();
	const int depth = p_.historyDepth;
	rDepth_ = createReader(pp, p_.depthTopic, sensor_msgs_msg_dds__Image__desc,
	                       depth);
	if (topicGiven(p_.colourTopic))
		rColour_ = createReader(pp, p_.colourTopic,
		                        sensor_msgs_msg_dds__Image__desc, depth);
	if (topicGiven(p_.cameraInfoTopic))
		rInfo_ = createReader(pp, p_.cameraInfoTopic,
		                      sensor_msgs_msg_dds__CameraInfo__desc, depth);
	if (topicGiven(p_.imuTopic))
		rImu_ = createReader(pp, p_.imuTopic, sensor_msgs_msg_dds__Imu__desc,
		                     // IMU samples come ~10x as often as frames
		                     std::max(depth, 50));
	if (topicGiven(p_.magTopic))
		rMag_ = createReader(pp, p_.magTopic,
		                     sensor_msgs_msg_dds__MagneticField__desc,
		                     std::max(depth, 50));
	rPubs_ = ddsCheck(dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSPUBLICATION,
	                                    nullptr, nullptr),
	                  "DDS publication reader");
	wMask_ =
	    createWriter(pp, p_.maskTopic, sensor_msgs_msg_dds__Image__desc, depth);
	wOdom_ = createWriter(pp, p_.odometryTopic,
	                      nav_msgs_msg_dds__Odometry__desc, depth);
	wPoints_ = createWriter(pp, p_.pointsTopic,
	                        sensor_msgs_msg_dds__PointCloud2__desc, depth);
	opt_.log(opt_.program + ": reading " + p_.depthTopic +
	         (topicGiven(p_.colourTopic) ? ", " + p_.colourTopic : "") +
	         (topicGiven(p_.imuTopic) ? ", " + p_.imuTopic : "") +
	         "; publishing " + p_.maskTopic + ", " + p_.odometryTopic + ", " +
	         p_.pointsTopic + " (DDS domain " + std::to_string(p_.domainId) +
	         ")");
	std::exception_ptr failed;
	std::thread worker(
	    [&]
	    {
		    try
		    {
			    process();
		    }
		    catch (...)
		    {
			    failed = std::current_exception();
			    done_ = true;
			    // leave the queue to be drained by nobody: the receiver
			    // stops at done_
		    }
	    });
	receive();
	worker.join();
	if (failed) std::rethrow_exception(failed);
	return st_;
}

}  // namespace

NodeStats runNode(const pipeline::ExperimentConfig& cfg, const Ros2Params& p,
                  const NodeOptions& opt)
{
	Node n(cfg, p, opt);
	return n.run();
}

std::string formatStats(const NodeStats& s)
{
	return std::to_string(s.framesProcessed) + " frames processed of " +
	       std::to_string(s.depthReceived) + " depth images received; " +
	       std::to_string(s.framesDropped) +
	       " dropped (arrived faster than processed), " +
	       std::to_string(s.framesRejected) + " not usable, " +
	       std::to_string(s.messagesRejected) + " messages not decoded; " +
	       std::to_string(s.imuReceived) + " IMU samples";
}

}  // namespace bims::ros2
