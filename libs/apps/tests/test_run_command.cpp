// bims-run's command (bims/apps/run_command.h): --variant, the exit code,
// --print-config.
#include <bims/apps/app.h>
#include <bims/apps/run_command.h>
#include <gtest/gtest.h>

#include <csignal>
#include <string>
#include <vector>

TEST(RunCommand, VariantOptionSetsTheVariantOrIsAUsageError)
{
	bims::pipeline::ExperimentConfig cfg;
	bims::apps::applyVariantOption(cfg, "fused-raycast");
	EXPECT_EQ(cfg.pipeline.variant, bims::pipeline::Variant::FusedRaycast);
	bims::apps::applyVariantOption(cfg, "flow-only");
	EXPECT_EQ(cfg.pipeline.variant, bims::pipeline::Variant::FlowOnly);
	try
	{
		bims::apps::applyVariantOption(cfg, "bogus");
		FAIL() << "no error for --variant bogus";
	}
	catch (const bims::UsageError& e)
	{
		EXPECT_EQ(std::string(e.what()).rfind("--variant: ", 0), 0u)
		    << e.what();
		EXPECT_NE(std::string(e.what()).find("bogus"), std::string::npos)
		    << e.what();
	}
	EXPECT_EQ(cfg.pipeline.variant, bims::pipeline::Variant::FlowOnly);
}

TEST(RunCommand, ExitCodeOfARunIsItsStatus)
{
	bims::pipeline::RunSummary s;
	EXPECT_EQ(bims::apps::runExitCode(s, 0), 0);
	s.error = "truncated";
	EXPECT_EQ(bims::apps::runExitCode(s, 0), 1);
	s.interrupted = true;  // interrupted wins: 128 + the signal
	EXPECT_EQ(bims::apps::runExitCode(s, SIGTERM), 128 + SIGTERM);
	EXPECT_EQ(bims::apps::runExitCode(s, 0), 128 + SIGINT);
}

TEST(RunCommand, PrintConfigTakesAtMostOneIniAndNothingElse)
{
	auto call = [](std::vector<std::string> words)
	{
		std::vector<char*> argv;
		for (auto& w : words) argv.push_back(w.data());
		return bims::apps::printConfigIfAsked(static_cast<int>(argv.size()),
		                                      argv.data());
	};
	EXPECT_FALSE(call({"bims-run", "a.ini", "b.rawlog", "-o", "out"}));
	EXPECT_THROW(call({"bims-run", "--print-config", "a.ini", "b.ini"}),
	             bims::UsageError);
	EXPECT_THROW(call({"bims-run", "--print-config", "-q"}), bims::UsageError);
	testing::internal::CaptureStdout();
	const auto rc = call({"bims-run", "--print-config"});
	const std::string out = testing::internal::GetCapturedStdout();
	ASSERT_TRUE(rc);
	EXPECT_EQ(*rc, 0);
	EXPECT_NE(out.find("[pipeline]"), std::string::npos) << out;
}
