// bims-import-stray FOLDER -o OUT.rawlog [--config stray.ini]
//   [--max-frames N] [--gz L] [-q]
// Converts a Stray Scanner capture (depth/, confidence/, rgb.mp4,
// camera_matrix.csv, odometry.csv, imu.csv) into a bims rawlog plus ARKit's
// poses in OUT_arkit_reference.txt. See docs/eval.md.
#include <bims/apps/app.h>
#include <bims/apps/stray_import_run.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-import-stray",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "Import a Stray Scanner capture (the iPhone/iPad LiDAR app's "
		        "folder: depth/, confidence/, optional rgb.mp4, "
		        "camera_matrix.csv, odometry.csv, imu.csv) into a rawlog of "
		        "RGB-D frames and IMU samples, plus ARKit's poses as a "
		        "reference (not ground truth) in OUT_arkit_reference.txt.",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> folder(
		        "FOLDER", "Stray Scanner capture folder", true, "", "FOLDER",
		        cmd);
		    TCLAP::ValueArg<std::string> out(
		        "o", "out",
		        "output rawlog (ARKit's poses go to OUT_arkit_reference.txt)",
		        true, "", "OUT.rawlog", cmd);
		    TCLAP::ValueArg<std::string> config(
		        "c", "config",
		        "experiment .ini: [import_stray] (min_confidence, colour "
		        "size), [sensors] labels (e.g. the preset stray.ini)",
		        false, "", "stray.ini", cmd);
		    TCLAP::ValueArg<long> maxFrames(
		        "", "max-frames", "import only the first N frames (0 = all)",
		        false, 0, "N", cmd);
		    TCLAP::ValueArg<int> gz(
		        "", "gz", "gzip level of the rawlog, 0 = plain (default 1)",
		        false, 1, "L", cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    bims::apps::StrayImportRunOptions o;
		    o.folder = folder.getValue();
		    o.out = out.getValue();
		    o.config = bims::givenValue(config);
		    o.max_frames = static_cast<size_t>(
		        bims::inRange(maxFrames, 0L, 100000000L, "0 = all"));
		    o.gz = gz.getValue();
		    o.progress = !quiet.getValue();
		    return bims::apps::runStrayImport(o);
	    });
}
