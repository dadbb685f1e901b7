// bims-ros2's parts that need no network: the drop-oldest frame queue and
// the strict [ros2] section.
#include <bims/common/config.h>
#include <bims/ros2/frame_queue.h>
#include <bims/ros2/params.h>
#include <gtest/gtest.h>

#include <bims_test/error_of.h>
#include <bims_test/tmp_dir.h>

#include <fstream>
#include <string>
#include <vector>

namespace
{
using namespace bims;

struct Item
{
	int id = 0;
	bool scan = false;  ///< a frame (else an IMU sample)
};

std::vector<int> drain(ros2::DropOldestQueue<Item>& q)
{
	q.close();
	std::vector<int> ids;
	while (auto it = q.pop()) ids.push_back(it->id);
	return ids;
}

TEST(FrameQueue, DropsTheOldestWaitingFrameAndCountsIt)
{
	ros2::DropOldestQueue<Item> q(2);
	EXPECT_EQ(q.push({1, true}), 0u);
	EXPECT_EQ(q.push({2, false}), 0u);
	EXPECT_EQ(q.push({3, true}), 0u);
	EXPECT_EQ(q.push({4, false}), 0u);
	// a third frame: the oldest (1) goes, the IMU samples stay
	EXPECT_EQ(q.push({5, true}), 1u);
	EXPECT_EQ(drain(q), (std::vector<int>{2, 3, 4, 5}));
}

TEST(FrameQueue, FramesTakenMakeRoomAndImuSamplesAreNeverDropped)
{
	ros2::DropOldestQueue<Item> q(1);
	EXPECT_EQ(q.push({1, true}), 0u);
	ASSERT_EQ(q.pop()->id, 1);
	EXPECT_EQ(q.push({2, true}), 0u);  // room again
	for (int i = 3; i < 13; i++) EXPECT_EQ(q.push({i, false}), 0u);
	EXPECT_EQ(q.push({13, true}), 1u);
	const auto ids = drain(q);
	ASSERT_EQ(ids.size(), 11u);
	EXPECT_EQ(ids.front(), 3);
	EXPECT_EQ(ids.back(), 13);
}

ros2::Ros2Params load(const std::string& section)
{
	const std::string ini = test::tmpPath("bims_ros2_units", "ros2.ini");
	std::ofstream(ini) << "[ros2]\n" << section;
	ros2::Ros2Params p;
	p.loadFromConfigFile(*openIniFile(ini));
	return p;
}

TEST(Ros2Params, UnknownKeysAndValuesOutOfRangeAreErrorsNamingTheKey)
{
	EXPECT_EQ(load("queue_frames = 7\n").queueFrames, 7);
	EXPECT_EQ(load("colour_topic = none\n").colourTopic, "none");
	for (const auto& [line, key] :
	     std::vector<std::pair<std::string, std::string>>{
	         {"queue_frame = 3\n", "queue_frame"},
	         {"queue_frames = 0\n", "queue_frames"},
	         {"domain_id = 233\n", "domain_id"},
	         {"depth_units = 0\n", "depth_units"},
	         {"depth_topic = camera/depth\n", "depth_topic"},
	         {"mask_topic = none\n", "mask_topic"}})
	{
		const std::string e = test::errorOf([&] { load(line); });
		EXPECT_NE(e.find("ros2"), std::string::npos) << line << e;
		EXPECT_NE(e.find(key), std::string::npos) << line << e;
	}
}

}  // namespace
