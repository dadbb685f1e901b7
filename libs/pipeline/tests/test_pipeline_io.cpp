// bims-run's writing thread (internal class): order, a failed job stops the
// rest and is reported.
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
