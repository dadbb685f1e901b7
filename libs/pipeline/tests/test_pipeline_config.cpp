#include <bims/common/config.h>
#include <bims/pipeline/config.h>
#include <bims/pipeline/run.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

using namespace bims::pipeline;

TEST(PipelineConfig, VariantNamesRoundTrip)
{
	for (auto v : {Variant::BottomOnly, Variant::FlowOnly, Variant::Fused,
	               Variant::FusedRaycast})
		EXPECT_EQ(variantFromString(toString(v)), v);
	EXPECT_THROW(variantFromString("fusion"), std::invalid_argument);
}

TEST(PipelineConfig, FusedRaycastSetsRaycastDecay)
{
	ExperimentConfig c;
	c.ego.odometry.mode = "vision";
	EXPECT_EQ(c.grids.decay, bims::maps::DecayMode::All);
	c.setVariant(Variant::FusedRaycast);
	EXPECT_EQ(c.grids.decay, bims::maps::DecayMode::Raycast);
}

TEST(PipelineConfig, ReadsEverySectionAndRejectsTypos)
{
	const char* ini =
	    "[odometry]\nmode = vision\n"
	    "[flow]\ndiff_threshold_px = 2\n"
	    "[grids]\nvoxel_size = 0.04\n"
	    "[pipeline]\nvariant = bottom-only\nwarmup_frames = 3\n"
	    "[output]\nmoving_ply = false\n";
	ExperimentConfig c;
	mrpt::config::CConfigFileMemory cfg(ini);
	c.loadFromConfigFile(cfg);
	EXPECT_EQ(c.pipeline.variant, Variant::BottomOnly);
	EXPECT_EQ(c.pipeline.warmup_frames, 3);
	EXPECT_FALSE(c.output.moving_ply);
	EXPECT_DOUBLE_EQ(c.flow.diff_threshold_px, 2.0);
	EXPECT_DOUBLE_EQ(c.grids.voxel_size, 0.04);

	mrpt::config::CConfigFileMemory typoKey(
	    "[odometry]\nmode = vision\n[pipeline]\nvarient = fused\n");
	EXPECT_THROW(c.loadFromConfigFile(typoKey), bims::ConfigError);
	mrpt::config::CConfigFileMemory typoSection(
	    "[odometry]\nmode = vision\n[pipline]\nvariant = fused\n");
	EXPECT_THROW(c.loadFromConfigFile(typoSection), bims::ConfigError);
	mrpt::config::CConfigFileMemory badVariant(
	    "[odometry]\nmode = vision\n[pipeline]\nvariant = both\n");
	EXPECT_THROW(c.loadFromConfigFile(badVariant), bims::ConfigError);
	EXPECT_THROW(c.loadFromFile("no/such/file.ini"), bims::ConfigError);
}

TEST(PipelineConfig, ThreadsAndLabelledRawlogCompression)
{
	ExperimentConfig c;
	EXPECT_TRUE(c.pipeline.read_ahead);
	EXPECT_TRUE(c.pipeline.flow_thread);
	EXPECT_TRUE(c.output.writer_thread);
	EXPECT_EQ(c.output.labelled_rawlog_gz_level, 0);
	mrpt::config::CConfigFileMemory ini(
	    "[odometry]\nmode = vision\n[pipeline]\nread_ahead = false\n"
	    "flow_thread = false\n"
	    "[output]\nwriter_thread = false\nlabelled_rawlog_gz_level = 6\n");
	c.loadFromConfigFile(ini);
	EXPECT_FALSE(c.pipeline.read_ahead);
	EXPECT_FALSE(c.pipeline.flow_thread);
	EXPECT_EQ(c.pipeline.opencv_threads, 0);
	mrpt::config::CConfigFileMemory cv1(
	    "[odometry]\nmode = vision\n[pipeline]\nopencv_threads = 1\n");
	c.loadFromConfigFile(cv1);
	EXPECT_EQ(c.pipeline.opencv_threads, 1);
	mrpt::config::CConfigFileMemory cvBad(
	    "[odometry]\nmode = vision\n[pipeline]\nopencv_threads = -1\n");
	EXPECT_THROW(c.loadFromConfigFile(cvBad), bims::ConfigError);
	EXPECT_FALSE(c.output.writer_thread);
	EXPECT_EQ(c.output.labelled_rawlog_gz_level, 6);
	mrpt::config::CConfigFileMemory bad(
	    "[odometry]\nmode = vision\n[output]\nlabelled_rawlog_gz_level = 10\n");
	try
	{
		c.loadFromConfigFile(bad);
		ADD_FAILURE() << "level 10 accepted";
	}
	catch (const bims::ConfigError& e)
	{
		EXPECT_NE(std::string(e.what()).find("labelled_rawlog_gz_level"),
		          std::string::npos)
		    << e.what();
	}
}

TEST(FrameRange, ParsesInclusiveRanges)
{
	auto r = FrameRange::parse("3:7");
	EXPECT_EQ(r.first, 3u);
	EXPECT_EQ(r.last, 7u);
	EXPECT_TRUE(r.contains(3));
	EXPECT_TRUE(r.contains(7));
	EXPECT_FALSE(r.contains(8));
	EXPECT_EQ(FrameRange::parse("5:").first, 5u);
	EXPECT_TRUE(FrameRange::parse(":4").contains(0));
	EXPECT_THROW(FrameRange::parse("7:3"), std::invalid_argument);
	EXPECT_THROW(FrameRange::parse("a:3"), std::invalid_argument);
	EXPECT_THROW(FrameRange::parse("3"), std::invalid_argument);
	EXPECT_THROW(FrameRange::parse("-1:3"), std::invalid_argument);
}

TEST(Percentiles, MedianAndP95)
{
	std::vector<double> v;
	for (int i = 1; i <= 100; i++) v.push_back(i);
	const auto p = Percentiles::of(v);
	EXPECT_DOUBLE_EQ(p.median, 51);
	EXPECT_DOUBLE_EQ(p.p95, 95);
	EXPECT_DOUBLE_EQ(p.mean, 50.5);
}
