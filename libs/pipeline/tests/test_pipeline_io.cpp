// bims-run's writing thread (internal class): order, a failed job stops the
// rest and is reported.
#include <bims/pipeline/mask_overlay.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "../src/worker.h"

using bims::pipeline::SerialWorker;

TEST(SerialWorker, RunsJobsInOrderWithAndWithoutAThread)
{
	for (bool threaded : {false, true})
	{
		std::vector<int> seen;
		SerialWorker w(3, threaded);
		EXPECT_EQ(w.threaded(), threaded);
		for (int i = 0; i < 200; i++) w.post([&seen, i] { seen.push_back(i); });
		w.drain();
		ASSERT_EQ(seen.size(), 200u);
		for (int i = 0; i < 200; i++) EXPECT_EQ(seen[i], i);
	}
}

TEST(SerialWorker, AFailedJobStopsTheRestAndIsReportedByPostAndDrain)
{
	for (bool threaded : {false, true})
	{
		std::vector<int> seen;
		SerialWorker w(4, threaded);
		auto post = [&](int i)
		{
			w.post(
			    [&seen, i]
			    {
				    if (i == 5)
					    throw std::runtime_error("out/x.png: disk full");
				    seen.push_back(i);
			    });
		};
		bool thrown = false;
		try
		{
			for (int i = 0; i < 50; i++) post(i);
			w.drain();
		}
		catch (const std::runtime_error& e)
		{
			thrown = true;
			EXPECT_STREQ(e.what(), "out/x.png: disk full");
		}
		EXPECT_TRUE(thrown);
		ASSERT_EQ(seen.size(), 5u);  // 0..4, nothing after the failure
		EXPECT_THROW(w.drain(), std::runtime_error);
		EXPECT_THROW(post(60), std::runtime_error);
		EXPECT_EQ(seen.size(), 5u);
	}
}

TEST(MaskOverlay, MovingPixelsHalfRedTheRestUnchanged)
{
	const cv::Mat grey(6, 8, CV_8UC1, cv::Scalar(100));
	cv::Mat mask(6, 8, CV_8UC1, cv::Scalar(0));
	mask.at<uint8_t>(2, 3) = 255;
	const cv::Mat o = bims::pipeline::overlayMoving(grey, mask);
	ASSERT_EQ(o.type(), CV_8UC3);
	EXPECT_EQ(o.at<cv::Vec3b>(2, 3), cv::Vec3b(50, 50, 178));
	EXPECT_EQ(o.at<cv::Vec3b>(0, 0), cv::Vec3b(100, 100, 100));
	EXPECT_EQ(cv::countNonZero(o.reshape(1) != 100), 3);
	// a mask of half the size covers the image, nearest
	const cv::Mat half(3, 4, CV_8UC1, cv::Scalar(255));
	const cv::Mat h = bims::pipeline::overlayMoving(grey, half);
	EXPECT_EQ(cv::countNonZero(h.reshape(1) == 178), 6 * 8);
	// no mask: the image as colour
	const cv::Mat n = bims::pipeline::overlayMoving(grey, cv::Mat());
	EXPECT_EQ(cv::countNonZero(n.reshape(1) != 100), 0);
}
