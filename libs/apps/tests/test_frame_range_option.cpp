// Every program's --frames A:B (frame_range_option.h): the library's plain
// errors become usage errors with the same message.
#include <bims/apps/app.h>
#include <bims/apps/frame_range_option.h>
#include <bims_test/sample.h>
#include <gtest/gtest.h>

#include <string>

using bims::apps::frameRangeOption;
using bims::test::kSample;

namespace
{
/** The UsageError message of frameRangeOption(text) ("" when none). */
std::string rangeUsageError(const std::string& text)
{
	try
	{
		frameRangeOption(text, {kSample}, "RGBD");
	}
	catch (const bims::UsageError& e)
	{
		return e.what();
	}
	return "";
}
}  // namespace

TEST(FrameRangeOption, NotGivenIsTheWholeInputAndARangeInItIsTaken)
{
	EXPECT_FALSE(frameRangeOption("", {kSample}, "RGBD").bounded());
	const auto r = frameRangeOption("3:7", {kSample}, "RGBD");
	EXPECT_EQ(r.first, 3u);
	EXPECT_EQ(r.last, 7u);
}

TEST(FrameRangeOption, BadTextAndARangeBeyondTheInputAreUsageErrors)
{
	EXPECT_EQ(rangeUsageError("a:3"),
	          "--frames 'a:3': 'a' is not a non-negative "
	          "integer");
	EXPECT_EQ(rangeUsageError("500:600"),
	          "--frames 500:600: the input (" + kSample +
	              ") has 150 3D scans (0 to 149) with label 'RGBD'");
}
