// The shared command-line plumbing (app.h) of every program.
#include <bims/apps/app.h>
#include <gtest/gtest.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <string>
#include <vector>

namespace
{
std::vector<std::string> renamed(std::vector<std::string> words)
{
	std::vector<char*> argv;
	for (auto& w : words) argv.push_back(w.data());
	const std::vector<bims::OptionName> known = {{"--max-frames", true},
	                                             {"--config", true},
	                                             {"-o", true},
	                                             {"-q", false}};
	return bims::renameOptions(
	    static_cast<int>(argv.size()), argv.data(),
	    {{"--frames", "--max-frames"}, {"--experiment", "--config"}}, known);
}
}  // namespace

TEST(App, OldSpellingsAreRewrittenWithANote)
{
	testing::internal::CaptureStderr();
	const auto args = renamed({"/x/bims-grab", "g.ini", "--frames", "30",
	                           "--experiment", "e.ini", "-q"});
	const std::string err = testing::internal::GetCapturedStderr();
	EXPECT_EQ(args,
	          (std::vector<std::string>{"/x/bims-grab", "g.ini", "--max-frames",
	                                    "30", "--config", "e.ini", "-q"}));
	EXPECT_EQ(err,
	          "bims-grab: note: --frames 30 is now --max-frames 30\n"
	          "bims-grab: note: --experiment e.ini is now --config e.ini\n");
}

TEST(App, ValuesAndWordsAfterDoubleDashAreNotRenamed)
{
	testing::internal::CaptureStderr();
	const auto args = renamed({"p", "-o", "--frames", "--", "--frames"});
	EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
	EXPECT_EQ(args, (std::vector<std::string>{"p", "-o", "--frames", "--",
	                                          "--frames"}));
}

TEST(App, GivenValueTellsAnOptionGivenEmptyFromOneNotGiven)
{
	TCLAP::CmdLine cmd("test", ' ', "0");
	TCLAP::ValueArg<std::string> a("", "csv", "a file", false, "d", "F", cmd);
	TCLAP::ValueArg<std::string> b("", "gt", "a file", false, "d", "F", cmd);
	TCLAP::ValueArg<size_t> n("", "max", "a count", false, 3, "N", cmd);
	std::vector<std::string> words = {"p", "--csv", "", "--max", "7"};
	std::vector<char*> argv;
	for (auto& w : words) argv.push_back(w.data());
	bims::parseCommandLine(cmd, static_cast<int>(argv.size()), argv.data());
	EXPECT_EQ(bims::givenValue(a), std::optional<std::string>(""));
	EXPECT_EQ(bims::givenValue(b), std::nullopt);
	EXPECT_EQ(bims::givenValue(n), std::optional<size_t>(7));
}
