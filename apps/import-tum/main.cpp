// bims-import-tum FOLDER -o OUT.rawlog [--config cam.ini] [--bonn-gt]
//   [--max-frames N] [--synth-imu [--seed N]] [--gz L]
// Converts a TUM RGB-D-layout folder into a bims rawlog plus OUT_gt/
// (groundtruth.txt, calibration.ini). See docs/eval.md.
#include <bims/apps/app.h>
#include <bims/apps/tum_import_run.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-import-tum",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "Import a TUM RGB-D-layout folder (rgb.txt, depth.txt, "
		        "optional accelerometer.txt, groundtruth.txt) into a rawlog of "
		        "registered RGB-D frames plus ground truth in OUT_gt/.",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> folder(
		        "FOLDER", "TUM RGB-D folder", true, "", "FOLDER", cmd);
		    TCLAP::ValueArg<std::string> out(
		        "o", "out", "output rawlog (ground truth goes to OUT_gt/)",
		        true, "", "OUT.rawlog", cmd);
		    TCLAP::ValueArg<std::string> config(
		        "c", "config",
		        "experiment .ini: [camera] intrinsics and depth_scale, "
		        "[import], [sensors] (default: TUM 525/319.5/239.5, depth "
		        "scale 5000)",
		        false, "", "cam.ini", cmd);
		    TCLAP::SwitchArg bonn(
		        "", "bonn-gt",
		        "ground truth is the Bonn RGB-D Dynamic marker pose: convert "
		        "it to the camera (same as [import] bonn_gt = true)",
		        cmd);
		    TCLAP::ValueArg<long> maxFrames(
		        "", "max-frames", "import only the first N frames (0 = all)",
		        false, 0, "N", cmd);
		    TCLAP::ValueArg<int> gz(
		        "", "gz", "gzip level of the rawlog, 0 = plain (default 1)",
		        false, 1, "L", cmd);
		    TCLAP::SwitchArg synth(
		        "", "synth-imu",
		        "add SYNTHETIC IMU readings (label <imu_label>_SYNTH) "
		        "synthesised from the ground truth with "
		        "bims::sim::synthesizeImu (default Xsens MTi-like noise; R_IC "
		        "and time_offset_s from [calibration] of --config)",
		        cmd);
		    TCLAP::ValueArg<uint64_t> seed(
		        "s", "seed", "random seed of --synth-imu (default 1)", false, 1,
		        "N", cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv, {{"--output", "--out"}});
		    bims::apps::ImportRunOptions o{
		        folder.getValue(),
		        out.getValue(),
		        bims::givenValue(config),
		        bonn.getValue(),
		        static_cast<size_t>(
		            bims::inRange(maxFrames, 0L, 100000000L, "0 = all")),
		        gz.getValue(),
		        synth.getValue(),
		        seed.getValue(),
		        !quiet.getValue(),
		        {}};
		    return bims::apps::runImport(o);
	    });
}
