// bims-sim: synthetic RGB-D + IMU sequences with ground truth.
//   bims-sim SCENE.ini -o OUT.rawlog [--seed N] [--max-frames N]
//            [--resolution 320x240] [--preview K] [-q]
//   bims-sim --imu-from-tum GT.txt -o IMU.rawlog [--seed N]
//            [--config imu.ini]
// See docs/sim.md.
#include <bims/apps/app.h>
#include <bims/apps/sim_run.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>

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
		        "scene",
		        "Scene .ini: a file, or a preset of share/bims by name "
		        "(sim/crowded.ini, sim/pendulum_slow.ini, ...)",
		        false, "", "SCENE.ini", cmd);
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
		    using bims::givenValue;
		    bims::apps::SimOptions o{givenValue(scene),    out.getValue(),
		                             seed.getValue(),      givenValue(frames),
		                             givenValue(res),      givenValue(tum),
		                             givenValue(config),   givenValue(preview),
		                             overwrite.getValue(), !quiet.getValue()};
		    // SIGINT / SIGTERM: stop after the current frame, write it all
		    if (o.scene && !o.imu_from_tum)
			    o.stop = &bims::installStopSignals();
		    return bims::apps::runSim(o);
	    });
}
