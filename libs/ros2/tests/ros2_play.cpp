// The loopback test's publisher (test_ros2_node): plays a rawlog as a
// RealSense driver's ROS 2 topics on Cyclone DDS (realsense-ros 4.x's names
// and types: depth 16UC1 in the scan's range units, colour bgr8,
// camera_info, imu, and the magnetic field on --mag-topic) and subscribes
// to the node's /bims/moving_mask and /bims/odometry. It never outruns the
// node: a depth image waits until at most --lag frames have no mask yet.
//
//   test_ros2_play IN.rawlog OUTDIR [--lag N] [--stop-pid PID]
//                  [--stop-after K] [--mag-topic T] [--bad-step K]
//                  [--wait-file PATH] [--frames K] [--wrong-type]
//
// OUTDIR/sent.csv: "sec,nsec" of each depth image sent; received.csv:
// "sec,nsec,width,height,encoding,frame_id" of each mask received, its
// pixels in masks/SEC_NSEC.png; odometry.txt: the count of odometry
// messages. --stop-pid: SIGINT to that process as soon as K frames are
// sent (--stop-after), or 0.2 s after the last one. --bad-step K: the K-th
// depth image (1-based) goes out with a step that disagrees with its data.
// --wait-file: play only once PATH exists (another subscriber is ready).
// --frames K: the first K frames only. --wrong-type: a second participant
// publishes sensor_msgs/Imu on the depth topic's name too. --realtime: every
// observation at its own time in the recording (a driver's rate; the node
// may fall behind and drop), the masks not written; OUTDIR/times.csv gets
// "sec,nsec,sent_ns,received_ns" of each depth image (steady clock; -1:
// no mask came) for bench/ros2_node.sh.
#include <bims/io/rawlog.h>
#include <bims/ros2/dds.h>
#include <bims/ros2/params.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>

#include "ros2_types.h"

namespace
{
using namespace bims::ros2;
using Clock = std::chrono::steady_clock;

int64_t nowNs()
{
	return std::chrono::duration_cast<std::chrono::nanoseconds>(
	           Clock::now().time_since_epoch())
	    .count();
}

struct Args
{
	std::string rawlog, outDir, magTopic = "none", waitFile;
	size_t lag = 2, stopAfter = 0, badStep = 0, frames = 0;
	int stopPid = 0;
	bool wrongType = false, realtime = false;
};

Args parse(int argc, char** argv)
{
	if (argc < 3)
		throw std::invalid_argument(
		    "usage: test_ros2_play IN.rawlog OUTDIR [--lag N] [--stop-pid "
		    "PID] [--stop-after K] [--mag-topic T] [--bad-step K]");
	Args a;
	a.rawlog = argv[1];
	a.outDir = argv[2];
	for (int i = 3; i < argc; i += 2)
	{
		const std::string k = argv[i];
		if (k == "--wrong-type" || k == "--realtime")
		{
			(k == "--realtime" ? a.realtime : a.wrongType) = true;
			i--;
			continue;
		}
		if (i + 1 == argc) throw std::invalid_argument(k + " needs a value");
		const std::string v = argv[i + 1];
		if (k == "--lag")
			a.lag = std::stoul(v);
		else if (k == "--stop-pid")
			a.stopPid = std::stoi(v);
		else if (k == "--stop-after")
			a.stopAfter = std::stoul(v);
		else if (k == "--mag-topic")
			a.magTopic = v;
		else if (k == "--bad-step")
			a.badStep = std::stoul(v);
		else if (k == "--wait-file")
			a.waitFile = v;
		else if (k == "--frames")
			a.frames = std::stoul(v);
		else
			throw std::invalid_argument("unknown option " + k);
	}
	return a;
}

builtin_interfaces_msg_dds__Time_ stampOf(mrpt::Clock::time_point t)
{
	// MRPT's ticks since 1970, in ns (the clock's epoch is 1601)
	const int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
	                       t - mrpt::Clock::fromDouble(0))
	                       .count();
	return {int32_t(ns / 1000000000), uint32_t(ns % 1000000000)};
}

dds_sequence_uint8 bytesOf(const void* data, size_t n)
{
	dds_sequence_uint8 s{};
	s._maximum = s._length = uint32_t(n);
	s._buffer = static_cast<uint8_t*>(const_cast<void*>(data));
	return s;
}

class Player
{
 public:
	explicit Player(const Args& a);
	void play();

 private:
	void waitForPeers();
	void collect();
	void sendImu(const mrpt::obs::CObservationIMU& o);
	void sendScan(const mrpt::obs::CObservation3DRangeScan& s);
	void stopNode();

	Args a_;
	Ros2Params p_;
	DdsEntity pp_, wrongPp_;
	dds_entity_t wDepth_, wColour_, wInfo_, wImu_, wMag_ = 0, rMask_, rOdom_;
	size_t sent_ = 0, received_ = 0, odometry_ = 0;
	using Stamp = std::pair<int32_t, uint32_t>;
	std::vector<std::pair<Stamp, int64_t>> sentNs_;  // steady clock [ns]
	std::map<Stamp, int64_t> receivedNs_;
	bool stopped_ = false;
	std::ofstream sentCsv_, receivedCsv_;
};

Player::Player(const Args& a) : a_(a)
{
	std::filesystem::create_directories(a_.outDir + "/masks");
	sentCsv_.open(a_.outDir + "/sent.csv");
	receivedCsv_.open(a_.outDir + "/received.csv");
	pp_ = DdsEntity(
	    ddsCheck(dds_create_participant(DDS_DOMAIN_DEFAULT, nullptr, nullptr),
	             "participant"));
	const auto pp = pp_.get();
	// as a sensor driver: best effort, volatile
	wDepth_ = createWriter(pp, p_.depthTopic, sensor_msgs_msg_dds__Image__desc,
	                       5, true);
	wColour_ = createWriter(pp, p_.colourTopic,
	                        sensor_msgs_msg_dds__Image__desc, 5, true);
	wInfo_ = createWriter(pp, p_.cameraInfoTopic,
	                      sensor_msgs_msg_dds__CameraInfo__desc, 5, true);
	wImu_ =
	    createWriter(pp, p_.imuTopic, sensor_msgs_msg_dds__Imu__desc, 50, true);
	if (topicGiven(a_.magTopic))
		wMag_ =
		    createWriter(pp, a_.magTopic,
		                 sensor_msgs_msg_dds__MagneticField__desc, 50, true);
	if (a_.wrongType)
	{
		wrongPp_ = DdsEntity(ddsCheck(
		    dds_create_participant(DDS_DOMAIN_DEFAULT, nullptr, nullptr),
		    "participant"));
		createWriter(wrongPp_.get(), p_.depthTopic,
		             sensor_msgs_msg_dds__Imu__desc, 5, true);
	}
	rMask_ =
	    createReader(pp, p_.maskTopic, sensor_msgs_msg_dds__Image__desc, 50);
	rOdom_ = createReader(pp, p_.odometryTopic,
	                      nav_msgs_msg_dds__Odometry__desc, 50);
}

void Player::waitForPeers()
{
	const auto t0 = Clock::now();
	for (;;)
	{
		dds_publication_matched_status_t w{};
		dds_subscription_matched_status_t r{};
		dds_get_publication_matched_status(wDepth_, &w);
		dds_get_subscription_matched_status(rMask_, &r);
		if (w.current_count > 0 && r.current_count > 0) break;
		if (Clock::now() - t0 > std::chrono::seconds(30))
			throw std::runtime_error("the node was not discovered in 30 s");
		std::this_thread::sleep_for(std::chrono::milliseconds(20));
	}
	while (!a_.waitFile.empty() && !std::filesystem::exists(a_.waitFile))
	{
		if (Clock::now() - t0 > std::chrono::seconds(30))
			throw std::runtime_error(a_.waitFile + " did not come in 30 s");
		std::this_thread::sleep_for(std::chrono::milliseconds(20));
	}
	// the node's other readers match at the same time as its depth reader
	std::this_thread::sleep_for(std::chrono::milliseconds(300));
}

void Player::collect()
{
	void* samples[8] = {};
	dds_sample_info_t infos[8];
	int n;
	while ((n = dds_take(rMask_, samples, infos, 8, 8)) > 0)
	{
		for (int i = 0; i < n; i++)
		{
			if (!infos[i].valid_data) continue;
			const auto* m =
			    static_cast<const sensor_msgs_msg_dds__Image_*>(samples[i]);
			const auto& t = m->header.stamp;
			receivedCsv_ << t.sec << "," << t.nanosec << "," << m->width << ","
			             << m->height << "," << m->encoding << ","
			             << m->header.frame_id << "\n";
			receivedNs_[{t.sec, t.nanosec}] = nowNs();
			if (!a_.realtime && m->data._length == size_t(m->width) * m->height)
				cv::imwrite(a_.outDir + "/masks/" + std::to_string(t.sec) +
				                "_" + std::to_string(t.nanosec) + ".png",
				            cv::Mat(int(m->height), int(m->width), CV_8UC1,
				                    m->data._buffer));
			received_++;
		}
		dds_return_loan(rMask_, samples, n);
	}
	while ((n = dds_take(rOdom_, samples, infos, 8, 8)) > 0)
	{
		for (int i = 0; i < n; i++) odometry_ += infos[i].valid_data;
		dds_return_loan(rOdom_, samples, n);
	}
}

void Player::sendImu(const mrpt::obs::CObservationIMU& o)
{
	using namespace mrpt::obs;
	const auto stamp = stampOf(o.timestamp);
	if (wMag_ && o.has(IMU_MAG_X))
	{
		sensor_msgs_msg_dds__MagneticField_ m{};
		m.header.stamp = stamp;
		m.header.frame_id = const_cast<char*>("imu");
		// gauss (MRPT) to tesla (ROS)
		m.magnetic_field = {o.get(IMU_MAG_X) * 1e-4, o.get(IMU_MAG_Y) * 1e-4,
		                    o.get(IMU_MAG_Z) * 1e-4};
		dds_write(wMag_, &m);
	}
	sensor_msgs_msg_dds__Imu_ m{};
	m.header.stamp = stamp;
	m.header.frame_id = const_cast<char*>("imu");
	if (o.has(IMU_ORI_QUAT_W))
		m.orientation = {o.get(IMU_ORI_QUAT_X), o.get(IMU_ORI_QUAT_Y),
		                 o.get(IMU_ORI_QUAT_Z), o.get(IMU_ORI_QUAT_W)};
	else
		m.orientation_covariance[0] = -1;
	if (o.has(IMU_WX))
		m.angular_velocity = {o.get(IMU_WX), o.get(IMU_WY), o.get(IMU_WZ)};
	else
		m.angular_velocity_covariance[0] = -1;
	if (o.has(IMU_X_ACC))
		m.linear_acceleration = {o.get(IMU_X_ACC), o.get(IMU_Y_ACC),
		                         o.get(IMU_Z_ACC)};
	else
		m.linear_acceleration_covariance[0] = -1;
	dds_write(wImu_, &m);
}

void Player::sendScan(const mrpt::obs::CObservation3DRangeScan& s)
{
	const auto stamp = stampOf(s.timestamp);
	char* frame = const_cast<char*>("camera_color_optical_frame");
	const auto& c = s.cameraParams;
	sensor_msgs_msg_dds__CameraInfo_ ci{};
	ci.header = {stamp, frame};
	ci.width = c.ncols;
	ci.height = c.nrows;
	ci.distortion_model = const_cast<char*>("plumb_bob");
	double d[5];
	for (int k = 0; k < 5; k++) d[k] = c.dist[k];
	ci.d = {5, 5, d, false};
	const double K[9] = {c.fx(), 0, c.cx(), 0, c.fy(), c.cy(), 0, 0, 1};
	std::copy(K, K + 9, ci.k);
	dds_write(wInfo_, &ci);
	if (s.hasIntensityImage)
	{
		const cv::Mat bgr = s.intensityImage.asCvMatRef();
		sensor_msgs_msg_dds__Image_ im{};
		im.header = {stamp, frame};
		im.width = uint32_t(bgr.cols);
		im.height = uint32_t(bgr.rows);
		im.encoding = const_cast<char*>("bgr8");
		im.step = uint32_t(bgr.step[0]);
		im.data = bytesOf(bgr.data, bgr.step[0] * bgr.rows);
		dds_write(wColour_, &im);
	}
	const auto& R = s.rangeImage;  // uint16, rangeUnits
	cv::Mat depth(int(R.rows()), int(R.cols()), CV_16UC1);
	for (int y = 0; y < depth.rows; y++)
		for (int x = 0; x < depth.cols; x++) depth.at<uint16_t>(y, x) = R(y, x);
	sensor_msgs_msg_dds__Image_ im{};
	im.header = {stamp, frame};
	im.width = uint32_t(depth.cols);
	im.height = uint32_t(depth.rows);
	im.encoding = const_cast<char*>("16UC1");
	im.step = uint32_t(depth.step[0]);
	if (sent_ + 1 == a_.badStep) im.step += 2;  // disagrees with the data
	im.data = bytesOf(depth.data, depth.step[0] * depth.rows);
	dds_write(wDepth_, &im);
	sentCsv_ << stamp.sec << "," << stamp.nanosec << std::endl;
	sentNs_.push_back({{stamp.sec, stamp.nanosec}, nowNs()});
	sent_++;
}

void Player::stopNode()
{
	if (a_.stopPid > 0 && !stopped_) kill(a_.stopPid, SIGINT);
	stopped_ = true;
}

void Player::play()
{
	waitForPeers();
	bims::RawlogReader in(a_.rawlog);
	const auto start = Clock::now();
	double t0 = -1;
	while (auto o = in.next())
	{
		collect();
		if (a_.realtime)
		{
			// at the observation's own time since the first one
			const double t = mrpt::Clock::toDouble(o->timestamp);
			if (t0 < 0) t0 = t;
			const auto due =
			    start + std::chrono::duration_cast<Clock::duration>(
			                std::chrono::duration<double>(t - t0));
			while (Clock::now() < due)
			{
				std::this_thread::sleep_for(std::chrono::microseconds(500));
				collect();
			}
		}
		if (auto imu = std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o))
		{
			sendImu(*imu);
			continue;
		}
		auto scan =
		    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(o);
		if (!scan) continue;
		scan->load();
		// never more than lag frames ahead of the node's masks
		const auto t0 = Clock::now();
		while (!a_.realtime &&
		       received_ + a_.lag + (a_.badStep && sent_ >= a_.badStep) <
		           sent_ + 1 &&
		       Clock::now() - t0 < std::chrono::seconds(60))
		{
			std::this_thread::sleep_for(std::chrono::milliseconds(2));
			collect();
		}
		sendScan(*scan);
		if (a_.stopAfter > 0 && sent_ == a_.stopAfter) stopNode();  // mid-run
		if (stopped_ || sent_ == a_.frames) break;
	}
	// the node then runs the frames it holds and publishes their masks
	std::this_thread::sleep_for(std::chrono::milliseconds(200));
	stopNode();
	const size_t expected = sent_ - (a_.badStep > 0);
	// until every mask came, or none for 10 s (frames dropped)
	auto last = Clock::now();
	while (received_ < expected &&
	       Clock::now() - last < std::chrono::seconds(10))
	{
		std::this_thread::sleep_for(std::chrono::milliseconds(5));
		const size_t before = received_;
		collect();
		if (received_ > before) last = Clock::now();
	}
	std::this_thread::sleep_for(std::chrono::milliseconds(300));
	collect();
	std::ofstream(a_.outDir + "/odometry.txt") << odometry_ << "\n";
	std::ofstream times(a_.outDir + "/times.csv");
	for (const auto& [stamp, ns] : sentNs_)
	{
		const auto it = receivedNs_.find(stamp);
		times << stamp.first << "," << stamp.second << "," << ns << ","
		      << (it == receivedNs_.end() ? -1 : it->second) << "\n";
	}
	std::printf("test_ros2_play: %zu depth images sent, %zu masks received\n",
	            sent_, received_);
}
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		Player(parse(argc, argv)).play();
		return 0;
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "test_ros2_play: %s\n", e.what());
		return 1;
	}
}
