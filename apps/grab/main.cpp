// bims-grab: live RGB-D (OpenNI2) + IMU (Xsens) grabbing into a rawlog,
// configured in rawlog-grabber style (one .ini section per sensor, driver=).
//
//   bims-grab GRAB.ini -o OUT.rawlog [--max-frames N] [--live-segmentation
//             [--config CONFIG.ini]] [--viewer] [-q]
//
// Ctrl-C stops cleanly (the rawlog is complete); the rawlog is flushed after
// every frame, so a kill or an unplug loses at most the last frame. No
// device: a clear message and exit code 1; --viewer without a display: the
// same, before any sensor is opened. See docs/grab.md; the logic:
// bims/apps/grab_run.h.
#include <bims/apps/app.h>
#include <bims/apps/grab_run.h>
#include <bims/apps/output_checks.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv)
{
	bims::keepFreedMemoryForReuse();
	return bims::runApp(
	    "bims-grab",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "bims-grab: grab RGB-D (OpenNI2) + IMU (Xsens) into a rawlog",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> aCfg(
		        "grab-config",
		        "grab .ini: the sensors (apps/grab/examples/*.ini)", true, "",
		        "GRAB.ini", cmd);
		    TCLAP::ValueArg<std::string> aOut("o", "out", "output rawlog", true,
		                                      "", "OUT.rawlog", cmd);
		    TCLAP::ValueArg<int> aFrames(
		        "", "max-frames",
		        "stop after N RGB-D frames (overrides [global] max_frames)",
		        false, 0, "N", cmd);
		    TCLAP::SwitchArg aSeg(
		        "", "live-segmentation",
		        "run the segmentation pipeline on the frames as they come",
		        cmd);
		    TCLAP::ValueArg<std::string> aExp(
		        "c", "config",
		        "experiment .ini for --live-segmentation (default: "
		        "share/bims/default.ini)",
		        false, "", "CONFIG.ini", cmd);
		    TCLAP::SwitchArg aViewer(
		        "", "viewer",
		        "show the RGB frames (with the moving mask) in a window", cmd);
		    TCLAP::SwitchArg aQuiet("q", "quiet", "no progress lines", cmd);
		    bims::parseCommandLine(
		        cmd, argc, argv,
		        {{"--frames", "--max-frames"}, {"--experiment", "--config"}});
		    bims::checkOutputsSpareInputs({aCfg.getValue(), aExp.getValue()},
		                                  {aOut.getValue()});
		    // Ctrl-C from now on: clean stop
		    const auto& stop = bims::installStopSignals();
		    bims::apps::GrabApp app({aCfg.getValue(), aOut.getValue(),
		                             bims::inRange(aFrames, 0, 100000000,
		                                           "0 = [global] max_frames"),
		                             aSeg.getValue(), aExp.getValue(),
		                             aViewer.getValue(), !aQuiet.getValue(),
		                             &stop});
		    const int code = app.run();
		    // The rawlog is closed and everything is printed: leave without
		    // the drivers' destructors. OpenNI2's Dummy driver crashes in its
		    // own thread at shutdown now and then under load (MRPT_NOTES), and
		    // a crash after a complete recording must not turn its exit code
		    // into a failure.
		    std::fflush(nullptr);
		    std::_Exit(code);
		    return 1;  // not reached
	    });
}
