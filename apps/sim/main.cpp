// bims-sim: synthetic RGB-D + IMU sequences with ground truth.
//   bims-sim SCENE.ini -o OUT.rawlog [--seed N] [--max-frames N]
//            [--resolution 320x240] [--preview K] [-q]
//   bims-sim --imu-from-tum GT.txt -o IMU.rawlog [--seed N]
//            [--config imu.ini]
// See docs/sim.md.
#include <bims/common/app.h>
#include <bims/common/config.h>
#include <bims/common/output_paths.h>
#include <bims/common/rawlog.h>
#include <bims/common/trajectory.h>
#include <bims/sim/imu.h>
#include <bims/sim/simulator.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>
#include <mrpt/config/CConfigFile.h>

#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>

namespace
{
int imuFromTum(const std::string& tum, const std::string& out, uint64_t seed,
               const std::string& iniPath)
{
	bims::sim::ImuParams p;
	if (!iniPath.empty())
	{
		std::ifstream f(iniPath);
		if (!f) throw std::runtime_error(iniPath + ": cannot open IMU config");
		bims::checkIniFile(iniPath);
		mrpt::config::CConfigFile ini(iniPath);
		bims::checkSections(ini, {"imu", "calibration"});
		p.loadFromConfigFile(ini, "imu", "calibration");
	}
	const auto traj = bims::loadTumTrajectory(tum);
	std::vector<bims::sim::ImuTruth> truth;
	const auto obs = bims::sim::synthesizeImu(traj, p, seed, &truth);
	bims::PartialFile part(out);  // renamed once complete
	bims::RawlogWriter w(part.path(), 1);
	for (const auto& o : obs) w.write(*o);
	w.close();
	part.commit();
	const std::string gtDir = bims::sim::groundTruthDirFor(out);
	bims::makeDirs(gtDir);
	bims::sim::saveImuTruth(gtDir + "/imu.txt", truth);
	std::fprintf(stderr,
	             "bims-sim: %zu synthetic IMU samples (label %s) from %zu "
	             "poses -> %s, truth in %s/imu.txt\n",
	             obs.size(),
	             obs.empty() ? "-" : obs.front()->sensorLabel.c_str(),
	             traj.size(), out.c_str(), gtDir.c_str());
	return 0;
}
}  // namespace

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-sim",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "Synthetic RGB-D + IMU sequences with ground truth (rawlog + "
		        "OUT_gt/).",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> scene(
		        "scene", "Scene .ini (see config/sim/)", false, "", "SCENE.ini",
		        cmd);
		    TCLAP::ValueArg<std::string> out("o", "out", "Output rawlog", true,
		                                     "", "OUT.rawlog", cmd);
		    TCLAP::ValueArg<uint64_t> seed(
		        "s", "seed", "Random seed (default 1)", false, 1, "N", cmd);
		    TCLAP::ValueArg<int> frames(
		        "", "max-frames",
		        "Number of RGB-D frames (overrides [sim] frames)", false, 0,
		        "N", cmd);
		    TCLAP::ValueArg<std::string> res(
		        "r", "resolution",
		        "640x480 or 320x240 (overrides [camera] resolution)", false, "",
		        "WxH", cmd);
		    TCLAP::ValueArg<std::string> tum(
		        "", "imu-from-tum",
		        "Synthesise only IMU data from a TUM trajectory (T_WC)", false,
		        "", "GT.txt", cmd);
		    TCLAP::ValueArg<std::string> config(
		        "c", "config",
		        "With --imu-from-tum: .ini with [imu] and [calibration]", false,
		        "", "imu.ini", cmd);
		    TCLAP::ValueArg<int> preview(
		        "", "preview",
		        "Also write OUT_gt/preview.png (RGB | depth | mask) of frame N",
		        false, -1, "N", cmd);
		    TCLAP::SwitchArg overwrite(
		        "", "overwrite",
		        "replace the ground truth of an earlier run in OUT_gt/ (its "
		        "files only; anything else there stays)",
		        cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "No progress bar", cmd);
		    bims::parseCommandLine(
		        cmd, argc, argv,
		        {{"--frames", "--max-frames"}, {"-f", "--max-frames"}});
		    bims::checkOutputsSpareInputs(
		        {scene.getValue(), tum.getValue(), config.getValue()},
		        {out.getValue(), bims::sim::groundTruthDirFor(out.getValue())});

		    // after the checks, before any work: an earlier run's ground
		    // truth would mix with this one's (a shorter run leaves its
		    // extra masks)
		    auto prepareGroundTruthDir = [&]
		    {
			    bims::prepareOutputFolder(
			        bims::sim::groundTruthDirFor(out.getValue()),
			        bims::sim::groundTruthLayout(), overwrite.getValue());
		    };
		    if (tum.isSet())
		    {
			    if (scene.isSet())
				    throw bims::UsageError(
				        "give either SCENE.ini or --imu-from-tum");
			    prepareGroundTruthDir();
			    return imuFromTum(tum.getValue(), out.getValue(),
			                      seed.getValue(), config.getValue());
		    }
		    if (!scene.isSet())
			    throw bims::UsageError("missing SCENE.ini (or --imu-from-tum)");
		    if (config.isSet())
			    throw bims::UsageError(
			        "--config only applies to --imu-from-tum");
		    auto cfg = bims::sim::SimConfig::load(scene.getValue());
		    if (frames.isSet())
		    {
			    if (frames.getValue() < 1)
				    throw bims::UsageError("--max-frames must be >= 1");
			    cfg.seq.frames = frames.getValue();
		    }
		    if (res.isSet())
		    {
			    try
			    {
				    cfg.camera.setResolution(res.getValue());
			    }
			    catch (const std::invalid_argument& e)
			    {
				    throw bims::UsageError(e.what());
			    }
		    }
		    if (preview.isSet() && (preview.getValue() < 0 ||
		                            preview.getValue() >= cfg.seq.frames))
			    throw bims::UsageError(
			        "--preview must be a frame index in [0, " +
			        std::to_string(cfg.seq.frames - 1) + "]");
		    // SIGINT / SIGTERM: stop after the current frame, write it all
		    prepareGroundTruthDir();
		    const auto& stop = bims::installStopSignals();
		    const auto st = bims::sim::runSimulation(
		        cfg, out.getValue(), seed.getValue(), !quiet.getValue(),
		        preview.getValue(), &stop);
		    std::fprintf(stderr,
		                 "bims-sim: %zu frames %dx%d + %zu IMU samples in %.2f "
		                 "s wall, %.2f s CPU "
		                 "(%.1f frames/s wall, %.1f frames/s per CPU second, "
		                 "render %.1f frames/s wall); "
		                 "moving pixels %.1f %%; ground truth in %s\n",
		                 st.frames, cfg.camera.width, cfg.camera.height,
		                 st.imuSamples, st.seconds, st.cpuSeconds,
		                 st.frames / st.seconds,
		                 st.frames / std::max(1e-9, st.cpuSeconds),
		                 st.frames / std::max(1e-9, st.renderSeconds),
		                 100 * st.movingFraction, st.gtDir.c_str());
		    if (st.interrupted)
		    {
			    const int sig = bims::stopSignal();
			    std::fprintf(
			        stderr,
			        "bims-sim: interrupted by %s after %zu of %d frames: "
			        "the rawlog and ground truth hold those frames, "
			        "complete\n",
			        sig == SIGTERM ? "SIGTERM" : "SIGINT", st.frames,
			        cfg.seq.frames);
			    return 128 + (sig ? sig : SIGINT);
		    }
		    return 0;
	    });
}
