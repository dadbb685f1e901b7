// bims-ros2 on the loopback of a private network namespace (unshare -rn:
// nothing leaves the machine): test_ros2_play (tests/ros2_play.cpp, on
// Cyclone DDS) plays the bundled sample as a RealSense driver's ROS 2
// topics, never more than two frames ahead of the node's masks, and
// subscribes to /bims/moving_mask. Every mask must come with its depth
// image's stamp, and the masks (received, and written by -o) must equal
// bims-run's on the same rawlog; an independent ROS 2 implementation,
// npm's @foxglove/ros2 (tests/ros2_writer/subscribe_masks.mjs), must get
// them too. Skipped, saying why, where the kernel refuses namespaces (and
// the independent subscriber's test where node or its package is missing).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <bims_test/run_command.h>
#include <bims_test/sample.h>
#include <bims_test/text.h>
#include <bims_test/tmp_dir.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace
{
namespace fs = std::filesystem;
using namespace bims;

const std::string kBin = BIMS_BIN_DIR;
const std::string kPlay = BIMS_ROS2_PLAY;
const std::string kDepthTopic =
    "/camera/camera/aligned_depth_to_color/image_raw";

/** Why a private network namespace cannot be made here ("": it can). */
std::string namespacesRefused()
{
	const auto r = test::runCommand(
	    "unshare -rn sh -c 'ip link set lo up && ip link set lo multicast on "
	    "&& ip route add 224.0.0.0/4 dev lo'");
	return r.code == 0 ? "" : "unshare -rn refused: " + r.out;
}

#define SKIP_WITHOUT_NAMESPACES()                                     \
	do                                                                \
	{                                                                 \
		const std::string why = namespacesRefused();                  \
		if (!why.empty())                                             \
			GTEST_SKIP() << "no private network namespace (the test " \
			                "would need the network otherwise): "     \
			             << why;                                      \
	} while (0)

/** The experiment: the default one with the sample's magnetometer topic
 * and its range units. */
std::string writeConfig(const std::string& dir)
{
	const std::string ini = dir + "/ros2.ini";
	std::ofstream(ini) << test::fileText(test::kDefaultConfig)
	                   << "\n[ros2]\nmag_topic = /camera/camera/mag\n"
	                      "depth_units = 0.001\nrange_units = 0.001\n";
	return ini;
}

struct Loopback
{
	int code = -1;        ///< of the script (the node's exit code)
	std::string nodeLog;  ///< bims-ros2's stdout and stderr
	std::string playLog;  ///< test_ros2_play's
	std::string playDir;  ///< sent.csv, received.csv, masks/
	std::string outDir;   ///< bims-ros2 -o
};

const std::string kSubscriber =
    std::string(BIMS_ROS2_WRITER_DIR) + "/subscribe_masks.mjs";

/** Why the independent subscriber (npm's @foxglove/ros2 under node)
 * cannot run here ("": it can). */
std::string subscriberMissing()
{
	if (test::runCommand("node --version").code != 0)
		return "node is not installed (scripts/install-deps.sh)";
	if (!fs::exists(std::string(BIMS_ROS2_WRITER_DIR) +
	                "/node_modules/@foxglove/ros2/package.json"))
		return "npm's @foxglove/ros2 is not installed (scripts/install-deps.sh "
		       "runs npm ci in tests/ros2_writer)";
	return "";
}

/** bims-ros2 CONFIG -o OUT and test_ros2_play in one private network
 * namespace (loopback with multicast, and the multicast route to it);
 * \a playArgs: the player's options; \a subscriber: the independent
 * subscriber too, into DIR/sub (the player waits for it). */
Loopback runLoopback(const std::string& dir, const std::string& playArgs,
                     bool subscriber = false)
{
	Loopback l;
	l.playDir = dir + "/play";
	l.outDir = dir + "/out";
	const std::string script = dir + "/loopback.sh";
	std::ofstream sh(script);
	sh << "ip link set lo up && ip link set lo multicast on && "
	      "ip route add 224.0.0.0/4 dev lo || exit 90\n"
	   << "export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces>"
	      "<NetworkInterface name=\"lo\" multicast=\"true\"/></Interfaces>"
	      "</General></Domain></CycloneDDS>'\n";
	if (subscriber)
		sh << "node '" << kSubscriber << "' '" << dir << "/sub' 60 > '" << dir
		   << "/sub.log' 2>&1 &\nSUB=$!\n";
	sh << "'" << kBin << "/bims-ros2' '" << writeConfig(dir) << "' -o '"
	   << l.outDir << "' > '" << dir << "/node.log' 2>&1 &\n"
	   << "NODE=$!\n"
	   << "'" << kPlay << "' '" << test::kSample << "' '" << l.playDir
	   << "' --stop-pid $NODE --mag-topic /camera/camera/mag " << playArgs
	   << (subscriber ? " --wait-file '" + dir + "/sub/ready'" : "") << " > '"
	   << dir << "/play.log' 2>&1\n"
	   << "kill -INT $NODE 2>/dev/null\n"  // the player failed: stop it
	   << "wait $NODE\nRC=$?\n";
	if (subscriber) sh << "sleep 1\nkill -TERM $SUB\nwait $SUB\n";
	sh << "exit $RC\n";
	sh.close();
	l.code = test::runCommand("unshare -rn sh '" + script + "'").code;
	l.nodeLog = test::fileText(dir + "/node.log");
	l.playLog = test::fileText(dir + "/play.log");
	return l;
}

std::vector<std::string> lines(const std::string& path)
{
	std::vector<std::string> v;
	std::ifstream in(path);
	for (std::string s; std::getline(in, s);)
		if (!s.empty()) v.push_back(s);
	return v;
}

/** "sec,nsec" of each mask received (DIR/received.csv, as test_ros2_play
 * and subscribe_masks.mjs write it). */
std::vector<std::string> receivedStamps(const std::string& dir)
{
	std::vector<std::string> v;
	for (const auto& s : lines(dir + "/received.csv"))
	{
		std::istringstream in(s);
		std::string sec, nsec, w, h, enc, frame;
		std::getline(in, sec, ',');
		std::getline(in, nsec, ',');
		std::getline(in, w, ',');
		std::getline(in, h, ',');
		std::getline(in, enc, ',');
		std::getline(in, frame);
		EXPECT_EQ(enc, "mono8") << s;
		EXPECT_EQ(frame, "camera_color_optical_frame") << s;
		v.push_back(sec + "," + nsec);
	}
	return v;
}

bool sameImage(const std::string& a, const std::string& b)
{
	const cv::Mat x = cv::imread(a, cv::IMREAD_UNCHANGED);
	const cv::Mat y = cv::imread(b, cv::IMREAD_UNCHANGED);
	return !x.empty() && x.size() == y.size() && x.type() == y.type() &&
	       cv::countNonZero(x != y) == 0;
}

/** bims-run's outputs of the sample, into DIR/run (each test its own:
 * CTest runs the cases in parallel processes). */
std::string runBimsRun(const std::string& dir)
{
	const auto r =
	    test::runCommand("'" + kBin + "/bims-run' '" + writeConfig(dir) +
	                     "' '" + test::kSample + "' -o '" + dir + "/run' -q");
	EXPECT_EQ(r.code, 0) << r.out;
	return dir + "/run";
}

std::string frameName(size_t i)
{
	std::string n = std::to_string(i);
	return std::string(6 - std::min<size_t>(6, n.size()), '0') + n + ".png";
}

/** How many of the masks received into \a dir (masks/SEC_NSEC\a ext, in
 * the order of \a stamps) are those of bims-run's output \a run. */
size_t sameMasks(const std::string& dir, const std::vector<std::string>& stamps,
                 const std::string& ext, const std::string& run)
{
	size_t same = 0;
	for (size_t i = 0; i < stamps.size(); i++)
	{
		std::string stamp = stamps[i];
		stamp[stamp.find(',')] = '_';
		same += sameImage(dir + "/masks/" + stamp + ext,
		                  run + "/masks/" + frameName(i));
	}
	return same;
}

size_t countMovingMasks(const std::string& dir)
{
	size_t n = 0;
	for (const auto& e : fs::directory_iterator(dir))
		n += cv::countNonZero(
		         cv::imread(e.path().string(), cv::IMREAD_UNCHANGED)) > 0;
	return n;
}

TEST(Ros2Node, EveryMaskComesWithItsDepthStampAndEqualsBimsRuns)
{
	SKIP_WITHOUT_NAMESPACES();
	const auto d = test::freshTmpDir("bims_ros2_node", "same");
	const auto l = runLoopback(d, "--lag 2");
	ASSERT_EQ(l.code, 0) << l.nodeLog << l.playLog;
	const auto sent = lines(l.playDir + "/sent.csv");
	const auto got = receivedStamps(l.playDir);
	ASSERT_EQ(sent.size(), 150u) << l.playLog;
	// every depth image's mask, with its stamp, in order
	EXPECT_EQ(got, sent) << l.nodeLog << l.playLog;
	EXPECT_NE(l.nodeLog.find("0 dropped"), std::string::npos) << l.nodeLog;
	EXPECT_EQ(lines(l.playDir + "/odometry.txt"),
	          std::vector<std::string>{"150"});
	// the masks received and those -o wrote are bims-run's
	const auto run = runBimsRun(d);
	ASSERT_EQ(lines(run + "/frames.csv").size(), 151u);
	EXPECT_EQ(lines(l.outDir + "/frames.csv").size(), 151u) << l.nodeLog;
	EXPECT_EQ(sameMasks(l.playDir, got, ".png", run), 150u);
	size_t sameOut = 0;
	for (size_t i = 0; i < got.size(); i++)
		sameOut += sameImage(l.outDir + "/masks/" + frameName(i),
		                     run + "/masks/" + frameName(i));
	EXPECT_EQ(sameOut, 150u);
	// not a vacuous equality: the pendulum moves in most frames
	EXPECT_GT(countMovingMasks(run + "/masks"), 100u);
	EXPECT_EQ(test::fileText(l.outDir + "/trajectory.txt"),
	          test::fileText(run + "/trajectory.txt"));
	EXPECT_TRUE(fs::exists(l.outDir + "/report.md"));
	const auto m =
	    nlohmann::json::parse(test::fileText(l.outDir + "/metrics.json"));
	EXPECT_EQ(m.at("status"), "ok");
}

TEST(Ros2Node, AnIndependentRos2SubscriberGetsEveryMaskWithItsStamp)
{
	SKIP_WITHOUT_NAMESPACES();
	const std::string why = subscriberMissing();
	if (!why.empty()) GTEST_SKIP() << "independent subscriber: " << why;
	const auto d = test::freshTmpDir("bims_ros2_node", "foxglove");
	const auto l = runLoopback(d, "--lag 2", true);
	ASSERT_EQ(l.code, 0) << l.nodeLog << l.playLog
	                     << test::fileText(d + "/sub.log");
	const auto sent = lines(l.playDir + "/sent.csv");
	ASSERT_EQ(sent.size(), 150u) << l.playLog;
	// @foxglove/ros2 (its own RTPS and CDR) got every mask, with its depth
	// image's stamp, in order, equal to bims-run's; and every odometry
	const auto got = receivedStamps(d + "/sub");
	EXPECT_EQ(got, sent) << test::fileText(d + "/sub.log");
	EXPECT_EQ(sameMasks(d + "/sub", got, ".pgm", runBimsRun(d)), 150u);
	EXPECT_EQ(lines(d + "/sub/odometry.txt"), std::vector<std::string>{"150"});
}

/** The number before \a what in \a text ("12 frames processed"). */
long numberBefore(const std::string& text, const std::string& what)
{
	const size_t at = text.find(" " + what);
	if (at == std::string::npos) return -1;
	size_t b = at;
	while (b > 0 && std::isdigit(static_cast<unsigned char>(text[b - 1]))) b--;
	return b == at ? -1 : std::stol(text.substr(b, at - b));
}

TEST(Ros2Node, SigintMidRunStopsItWithEveryOutputWhole)
{
	SKIP_WITHOUT_NAMESPACES();
	const auto d = test::freshTmpDir("bims_ros2_node", "sigint");
	// as fast as the player can: the node drops the oldest frames waiting
	// (how many depends on the machine: only the counts' sum is checked)
	const auto l = runLoopback(d, "--lag 1000 --stop-after 60");
	ASSERT_EQ(l.code, 0) << l.nodeLog << l.playLog;
	const long processed = numberBefore(l.nodeLog, "frames processed of");
	const long received = numberBefore(l.nodeLog, "depth images received");
	const long dropped = numberBefore(l.nodeLog, "dropped (arrived faster");
	// best effort: DDS may lose some of a flood before the node takes them
	EXPECT_GT(received, 0) << l.nodeLog;
	EXPECT_LE(received, 60) << l.nodeLog;
	EXPECT_EQ(processed + dropped, received) << l.nodeLog;
	ASSERT_GT(processed, 0) << l.nodeLog;
	const size_t n = size_t(processed);
	EXPECT_EQ(lines(l.outDir + "/frames.csv").size(), n + 1) << l.nodeLog;
	size_t poses = 0;
	for (const auto& s : lines(l.outDir + "/trajectory.txt"))
		poses += s[0] != '#';
	EXPECT_EQ(poses, n);
	size_t masks = 0;
	for (const auto& e : fs::directory_iterator(l.outDir + "/masks"))
		masks += !cv::imread(e.path().string(), cv::IMREAD_UNCHANGED).empty();
	EXPECT_EQ(masks, n);
	const auto m =
	    nlohmann::json::parse(test::fileText(l.outDir + "/metrics.json"));
	EXPECT_EQ(m.at("frames_processed"), n);
	EXPECT_EQ(m.at("status"), "ok");
	// the labelled rawlog whole: bims-info reads every frame of it
	const auto info = test::runCommand("'" + kBin + "/bims-info' '" + l.outDir +
	                                   "/segmented.rawlog'");
	EXPECT_EQ(info.code, 0) << info.out;
	// no partial file left behind
	for (const auto& e : fs::recursive_directory_iterator(l.outDir))
		EXPECT_EQ(e.path().string().find(".partial"), std::string::npos)
		    << e.path();
}

TEST(Ros2Node, AnImageWhoseStepDisagreesWithItsDataIsWarnedAboutNamingTheTopic)
{
	SKIP_WITHOUT_NAMESPACES();
	const auto d = test::freshTmpDir("bims_ros2_node", "step");
	const auto l = runLoopback(d, "--lag 2 --frames 12 --bad-step 6");
	ASSERT_EQ(l.code, 0) << l.nodeLog << l.playLog;
	const std::string want = "topic " + kDepthTopic +
	                         ": a message not used: its step 642 and size "
	                         "320x240 (2 bytes a pixel) disagree with its "
	                         "153600 bytes of data";
	EXPECT_NE(l.nodeLog.find(want), std::string::npos) << l.nodeLog;
	EXPECT_NE(l.nodeLog.find("1 messages not decoded"), std::string::npos)
	    << l.nodeLog;
	// the others all ran
	EXPECT_EQ(receivedStamps(l.playDir).size(), 11u) << l.playLog;
}

}  // namespace

namespace
{
TEST(Ros2Node, APeerPublishingAnotherTypeOnATopicIsWarnedAboutNamingIt)
{
	SKIP_WITHOUT_NAMESPACES();
	const auto d = test::freshTmpDir("bims_ros2_node", "type");
	const auto l = runLoopback(d, "--lag 2 --frames 12 --wrong-type");
	ASSERT_EQ(l.code, 0) << l.nodeLog << l.playLog;
	EXPECT_NE(l.nodeLog.find("topic " + kDepthTopic +
	                         ": a peer publishes type "
	                         "sensor_msgs::msg::dds_::Imu_, not "
	                         "sensor_msgs::msg::dds_::Image_"),
	          std::string::npos)
	    << l.nodeLog;
	// the right publisher's frames all ran
	EXPECT_EQ(receivedStamps(l.playDir).size(), 12u) << l.playLog;
}
}  // namespace
