// bims-ros2: the pipeline as a ROS 2 node on Cyclone DDS (no rclcpp).
//
//   bims-ros2 CONFIG.ini [-o OUTDIR [--overwrite]] [--max-frames N]
//
// Reads [ros2]'s depth, colour, camera_info and IMU topics (realsense-ros
// 4.x's by default), runs the pipeline on the frames as they arrive and
// publishes /bims/moving_mask, /bims/odometry, /bims/moving_points. Ctrl-C
// stops it after the frames received. With -o it writes what bims-run
// writes (pipeline::RunRecorder) and report.md. See docs/ros2.md; the node:
// bims/ros2/node.h.
#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>
#include <bims/apps/run_report.h>
#include <bims/common/config.h>
#include <bims/common/share.h>
#include <bims/ros2/node.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <cstdio>
#include <filesystem>

int main(int argc, char** argv)
{
	bims::keepFreedMemoryForReuse();
	return bims::runApp(
	    "bims-ros2",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "bims-ros2: the segmentation as a ROS 2 node (Cyclone DDS)",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> aCfg(
		        "config",
		        "experiment .ini with a [ros2] section: a file, or a preset of "
		        "share/bims by name",
		        true, "", "CONFIG.ini", cmd);
		    TCLAP::ValueArg<std::string> aOut(
		        "o", "out",
		        "output folder: what bims-run writes (masks, frames.csv, "
		        "metrics.json, ...)",
		        false, "", "OUTDIR", cmd);
		    TCLAP::SwitchArg aOverwrite(
		        "", "overwrite",
		        "replace the outputs of an earlier run in OUTDIR", cmd);
		    TCLAP::ValueArg<int> aFrames(
		        "", "max-frames", "stop after N frames processed (0: never)",
		        false, 0, "N", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    const int maxFrames =
		        bims::inRange(aFrames, 0, 100000000, "0 = never");
		    bims::pipeline::ExperimentConfig cfg;
		    cfg.loadFromFile(aCfg.getValue());
		    bims::ros2::Ros2Params p;
		    p.loadFromConfigFile(
		        *bims::openIniFile(bims::resolvePreset(aCfg.getValue())));
		    bims::ros2::NodeOptions opt;
		    opt.maxFrames = size_t(maxFrames);
		    opt.outDir = aOut.getValue();
		    if (!opt.outDir.empty())
		    {
			    opt.laterFiles = {"report.md"};
			    bims::prepareOutputFolder(opt.outDir,
			                              bims::pipeline::runOutputLayout(),
			                              aOverwrite.getValue());
		    }
		    opt.stop = &bims::installStopSignals();
		    opt.log = [](const std::string& line)
		    { std::fprintf(stderr, "%s\n", line.c_str()); };
		    const auto st = bims::ros2::runNode(cfg, p, opt);
		    std::printf("%s", bims::pipeline::formatSummary(st.run).c_str());
		    std::fprintf(stderr, "bims-ros2: %s\n",
		                 bims::ros2::formatStats(st).c_str());
		    if (!opt.outDir.empty() &&
		        std::filesystem::exists(opt.outDir + "/metrics.json"))
			    bims::apps::writeRunReport(
			        {opt.outDir,
			         {},
			         aCfg.getValue(),
			         bims::choiceName(cfg.ego.odometry.mode),
			         cfg.input});
		    if (!st.run.error.empty())
			    std::fprintf(stderr, "bims-ros2: error: %s\n",
			                 st.run.error.c_str());
		    return st.run.error.empty() ? 0 : 1;
	    });
}
