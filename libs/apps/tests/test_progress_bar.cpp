// The progress line of every program (progress_bar.h) and the callback the
// libraries report to.
#include <bims/apps/progress_bar.h>
#include <gtest/gtest.h>

#include <string>

TEST(Progress, APlainLineHasTotalShareRateAndEta)
{
	bims::ProgressBar bar("bims-run", 150, false);
	EXPECT_EQ(
	    bar.text(45, 3.0, false),
	    "bims-run: 45/150 frames (30 %), 15.0 frames/s, 3.0 s, ETA 7.0 s");
	EXPECT_EQ(bar.text(150, 10.0, false, "frame 149"),
	          "bims-run: 150/150 frames (100 %), 15.0 frames/s, 10.0 s, "
	          "frame 149");
	bar.setTotal(1500, true);  // estimated
	EXPECT_EQ(bar.text(450, 30.0, false),
	          "bims-run: 450/~1500 frames (30 %), 15.0 frames/s, 30.0 s, ETA "
	          "1 min 10 s");
	bims::ProgressBar open("bims-odom", 0, false);
	EXPECT_EQ(open.text(20, 2.0, false),
	          "bims-odom: 20 frames, 10.0 frames/s, 2.0 s");
}

TEST(Progress, ATerminalLineHasABarAndNoLineEnd)
{
	bims::ProgressBar bar("bims-sim", 100, false);
	const std::string t = bar.text(50, 5.0, true, "x");
	EXPECT_EQ(t,
	          "bims-sim [############            ] 50/100 frames 50 % 10.0/s "
	          "ETA 5.0 s x");
	EXPECT_EQ(t.find_first_of("\r\n"), std::string::npos);
}

TEST(Progress, DurationsReadAsMinutesAndHours)
{
	EXPECT_EQ(bims::formatDuration(8.46), "8.5 s");
	EXPECT_EQ(bims::formatDuration(125), "2 min 05 s");
	EXPECT_EQ(bims::formatDuration(3725), "1 h 02 min");
}

TEST(Progress, ABarOffGivesNoCallbackAndAReportSetsItsTotal)
{
	bims::ProgressBar off("bims-run", 0, false);
	EXPECT_FALSE(off.callback());  // -q: the library reports to nobody
	bims::ProgressBar bar("import", 0, true);
	const auto at = [](size_t done, size_t total, bool estimated = false,
	                   bool finished = false)
	{
		bims::Progress p;
		p.done = done;
		p.total = total;
		p.estimated = estimated;
		p.finished = finished;
		return p;
	};
	testing::internal::CaptureStderr();
	const auto cb = bar.callback();
	ASSERT_TRUE(cb);
	cb(at(0, 20));
	cb(at(10, 20));
	cb(at(20, 20, false, true));
	const std::string err = testing::internal::GetCapturedStderr();
	// one final line for the whole total (stderr is no terminal here)
	EXPECT_NE(err.find("import: 20/20 frames (100 %)"), std::string::npos)
	    << err;
	// an estimated total prints as "~N"
	testing::internal::CaptureStderr();
	bar.report(at(5, 50, true));
	testing::internal::GetCapturedStderr();
	EXPECT_EQ(bar.text(5, 1.0, false).rfind("import: 5/~50 frames", 0), 0u);
}
