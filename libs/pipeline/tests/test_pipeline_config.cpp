#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/pipeline/config.h>
#include <bims/pipeline/run.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <csignal>
#include <fstream>
#include <iterator>
#include <sstream>

using namespace bims::pipeline;

namespace
{
const std::string kConfigDir = std::string(BIMS_SOURCE_DIR) + "/config/";

ExperimentConfig loaded(const std::string& name)
{
	ExperimentConfig c;
	c.loadFromFile(kConfigDir + name);
	return c;
}
ExperimentConfig fromText(const std::string& ini)
{
	ExperimentConfig c;
	mrpt::config::CConfigFileMemory m(ini);
	c.loadFromConfigFile(m);
	return c;
}
}  // namespace

TEST(PipelineConfig, TheBuiltInDefaultsAreConfigDefaultIni)
{
	// A program without an .ini runs the model of bims-run
	// config/default.ini: every key of every section (the text holds each
	// value exactly), and what the text does not show.
	const ExperimentConfig builtIn, file = loaded("default.ini");
	EXPECT_EQ(file.effectiveIni(), builtIn.effectiveIni());
	EXPECT_EQ(file.ego.calibration.has_R_IC, builtIn.ego.calibration.has_R_IC);
	EXPECT_EQ(file.ego.calibration.R_IC, builtIn.ego.calibration.R_IC);
	EXPECT_EQ(file.ego.camera.given, builtIn.ego.camera.given);
	// and a few of the tuned keys by name
	EXPECT_EQ(builtIn.grids.decay, bims::maps::DecayMode::Raycast);
	EXPECT_EQ(builtIn.grids.p_unknown, 0.97);
	EXPECT_TRUE(builtIn.grids.exclude_moving);
	EXPECT_TRUE(builtIn.flow.derotate);
	EXPECT_EQ(builtIn.flow.dis_preset, bims::flow::DisPreset::Auto);
	EXPECT_EQ(builtIn.ego.sensors.imu_label, "IMU");
}

TEST(PipelineConfig, ThePaperPresetIsTheLiteralModel)
{
	const ExperimentConfig p = loaded("paper.ini");
	EXPECT_EQ(p.grids.decay, bims::maps::DecayMode::All);
	EXPECT_EQ(p.grids.p_unknown, 0.0);
	EXPECT_EQ(p.grids.bg_neighbourhood, bims::maps::BgNeighbourhood::None);
	EXPECT_FALSE(p.grids.exclude_moving);
	EXPECT_EQ(p.grids.p_max, 0.97);
	EXPECT_FALSE(p.flow.derotate);
	EXPECT_EQ(p.flow.visible_change_grey, 0.0);
	EXPECT_EQ(p.flow.diff_threshold_px, 1.5);
	// every key it gives (R_IC aside: an experiment file must) changes the
	// model: the preset says nothing the defaults already say
	mrpt::config::CConfigFile paper(kConfigDir + "paper.ini");
	std::vector<std::string> sections, keys;
	paper.getAllSections(sections);
	for (const auto& s : sections)
	{
		paper.getAllKeys(s, keys);
		for (const auto& k : keys)
		{
			if (k == "R_IC") continue;
			EXPECT_NE(fromText("[" + s + "]\n" + k + " = " +
			                   paper.read_string(s, k, "") +
			                   "\n[calibration]\nR_IC = 0 0 1 -1 0 0 0 -1 0\n")
			              .effectiveIni(),
			          ExperimentConfig().effectiveIni())
			    << "[" << s << "] " << k << " is the default";
		}
	}
}

TEST(PipelineConfig, EffectiveIniReadBackIsTheSameConfiguration)
{
	auto raycast = loaded("default.ini");
	raycast.setVariant(Variant::FusedRaycast);  // as bims-run --variant
	std::vector<std::pair<std::string, ExperimentConfig>> cases = {
	    {"default.ini", loaded("default.ini")},
	    {"paper.ini", loaded("paper.ini")},
	    {"bonn.ini", loaded("bonn.ini")},
	    {"stray.ini", loaded("stray.ini")},
	    {"realsense.ini", loaded("realsense.ini")},
	    {"default.ini --variant fused-raycast", raycast}};
	for (const auto& [name, c] : cases)
	{
		const std::string text = c.effectiveIni();
		const ExperimentConfig r = fromText(text);
		EXPECT_EQ(r.effectiveIni(), text) << name;
		EXPECT_EQ(r.ego.calibration.R_IC, c.ego.calibration.R_IC) << name;
		EXPECT_EQ(r.ego.camera.given, c.ego.camera.given) << name;
		EXPECT_EQ(r.pipeline.variant, c.pipeline.variant) << name;
		EXPECT_EQ(r.grids.decay, c.grids.decay) << name;
	}
	// what the Bonn file sets, kept: intrinsics, labels, depth correction
	const ExperimentConfig bonn = fromText(loaded("bonn.ini").effectiveIni());
	EXPECT_TRUE(bonn.ego.camera.given);
	EXPECT_EQ(bonn.ego.camera.fx, 542.822841);
	EXPECT_EQ(bonn.ego.sensors.imu_label, "IMU_SYNTH");
	EXPECT_TRUE(bonn.ego.depth_correction.enable);
	EXPECT_EQ(bonn.flow.refine_pose, bims::flow::RefinePose::SE3);
	// an R_IC that is a rotation only to 1e-4 is re-orthonormalised once;
	// written out, it reads back bit for bit
	const ExperimentConfig tilted =
	    fromText("[calibration]\nR_IC = 0 0 1  -1 0 0.0001  0 -1 0\n");
	EXPECT_EQ(fromText(tilted.effectiveIni()).ego.calibration.R_IC,
	          tilted.ego.calibration.R_IC);
}

TEST(PipelineConfig, TheRealSensePresetGivesTheImuInTheOpticalFrame)
{
	// config/realsense.ini (bims-import-bag's [import_bag] aside):
	// realsense-ros's IMU in the optical axes, no magnetometer
	const ExperimentConfig s = loaded("realsense.ini");
	EXPECT_EQ(s.ego.calibration.R_IC, Eigen::Matrix3d::Identity());
	EXPECT_TRUE(s.ego.calibration.has_R_IC);
	EXPECT_FALSE(s.ego.attitude.use_magnetometer);
	EXPECT_EQ(s.ego.sensors.imu_label, "IMU");
}

TEST(PipelineConfig, TheStrayPresetGivesTheIphoneImuMounting)
{
	// config/stray.ini (bims-import-stray's [import_stray] aside, which
	// bims-run accepts unread): R_IC = R_CI^T of the data's README, the
	// clock offset, no magnetometer, the importer's labels
	const ExperimentConfig s = loaded("stray.ini");
	Eigen::Matrix3d R;
	R << 0, -1, 0, -1, 0, 0, 0, 0, -1;
	EXPECT_EQ(s.ego.calibration.R_IC, R);
	EXPECT_TRUE(s.ego.calibration.has_R_IC);
	EXPECT_EQ(s.ego.calibration.time_offset_s, 0);
	EXPECT_FALSE(s.ego.attitude.use_magnetometer);
	EXPECT_EQ(s.ego.sensors.rgbd_label, "RGBD");
	EXPECT_EQ(s.ego.sensors.imu_label, "IMU");
	EXPECT_FALSE(s.ego.camera.given);  // each scan's own intrinsics
	// the LiDAR's grids: ray-cast free space, nothing beyond 3.5 m
	EXPECT_EQ(s.grids.decay, bims::maps::DecayMode::Raycast);
	EXPECT_EQ(s.grids.max_range, 3.5);
}

TEST(PipelineConfig, EffectiveIniHasEverySectionAndAMeaningPerKey)
{
	const std::string text = ExperimentConfig().effectiveIni();
	mrpt::config::CConfigFileMemory m(text);
	std::vector<std::string> sections;
	m.getAllSections(sections);
	// all but [camera] (only when a file gives intrinsics), [import]
	// (bims-import-tum's), [import_stray] (bims-import-stray's),
	// [import_bag] (bims-import-bag's) and [ros2] (bims-ros2's)
	EXPECT_EQ(sections.size(), bims::experimentSections().size() - 5);
	for (const char* s :
	     {"sensors", "calibration", "depth_correction", "attitude", "tracker",
	      "translation", "odometry", "anchor", "inertial", "flow", "grids",
	      "pipeline", "output"})
		EXPECT_TRUE(m.sectionExists(s)) << s;
	EXPECT_NE(text.find("\ndecay = raycast // "), std::string::npos);
	EXPECT_NE(text.find("\nvariant = fused // "), std::string::npos);
	EXPECT_NE(fromText("[camera]\nfx=500\nfy=500\ncx=320\ncy=240\n"
	                   "width=640\nheight=480\n"
	                   "[calibration]\nR_IC = 0 0 1 -1 0 0 0 -1 0\n")
	              .effectiveIni()
	              .find("[camera]\nfx = 500 // "),
	          std::string::npos);
	// no key without its meaning
	std::istringstream lines(text);
	for (std::string l; std::getline(lines, l);)
	{
		if (l.find(" = ") == std::string::npos) continue;
		EXPECT_NE(l.find(" // "), std::string::npos) << l;
	}
}

TEST(ConfigReference, DocsConfigMdIsUpToDate)
{
	// docs/config.md is generated from the same description as
	// effective.ini and bims-run --print-config
	const std::string now = configReference();
	std::ifstream f(std::string(BIMS_SOURCE_DIR) + "/docs/config.md");
	const std::string doc{std::istreambuf_iterator<char>(f), {}};
	if (doc != now)
	{
		const std::string fresh = std::string(BIMS_BINARY_DIR) + "/config.md";
		std::ofstream(fresh) << now;
		FAIL() << "docs/config.md is out of date: copy " << fresh << " over it";
	}
	// every key of every section is in it
	mrpt::config::CConfigFileMemory m(ExperimentConfig().effectiveIni());
	std::vector<std::string> sections, keys;
	m.getAllSections(sections);
	for (const auto& s : sections)
	{
		EXPECT_NE(now.find("## [" + s + "]"), std::string::npos) << s;
		m.getAllKeys(s, keys);
		for (const auto& k : keys)
			EXPECT_NE(now.find("| `" + k + "` |"), std::string::npos) << k;
	}
	EXPECT_NE(now.find("| `fx` | `(none)` |"), std::string::npos);
}

TEST(PipelineConfig, VariantNamesRoundTrip)
{
	for (auto v : {Variant::BottomOnly, Variant::FlowOnly, Variant::Fused,
	               Variant::FusedRaycast})
		EXPECT_EQ(bims::parseChoice<Variant>(bims::choiceName(v)), v);
	try
	{
		bims::parseChoice<Variant>("fusion");
		ADD_FAILURE() << "expected std::invalid_argument";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_STREQ(e.what(),
		             "'fusion' is not one of "
		             "bottom-only|flow-only|fused|fused-raycast");
	}
}

TEST(PipelineConfig, FusedRaycastSetsRaycastDecay)
{
	ExperimentConfig c;
	c.ego.odometry.mode = bims::ego::OdometryMode::Vision;
	c.grids.decay = bims::maps::DecayMode::Frustum;
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
