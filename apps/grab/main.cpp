// bims-grab: live RGB-D (OpenNI2) + IMU (Xsens) grabbing into a rawlog,
// configured in rawlog-grabber style (one .ini section per sensor, driver=).
//
//   bims-grab GRAB.ini -o OUT.rawlog [--max-frames N] [--live-segmentation
//             [--config CONFIG.ini]] [--viewer] [-q]
//
// Ctrl-C stops cleanly (the rawlog is complete); the rawlog is flushed after
// every frame, so a kill or an unplug loses at most the last frame. No
// device: a clear message and exit code 1; --viewer without a display: the
// same, before any sensor is opened. See docs/grab.md.
#include <bims/common/app.h>
#include <bims/common/config.h>
#include <bims/common/output_paths.h>
#include <bims/common/progress.h>
#include <bims/common/share.h>
#include <bims/grab/grabber.h>
#include <bims/pipeline/stepper.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/gui/CDisplayWindow.h>
#include <mrpt/system/filesystem.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <opencv2/imgproc.hpp>

namespace
{
/** RGB with the moving mask in red (live preview). */
mrpt::img::CImage preview(const mrpt::obs::CObservation3DRangeScan& scan,
                          const cv::Mat& mask)
{
	if (!scan.hasIntensityImage) return {};
	cv::Mat bgr = scan.intensityImage.asCvMatRef().clone();
	if (bgr.channels() == 1) cv::cvtColor(bgr, bgr, cv::COLOR_GRAY2BGR);
	if (!mask.empty() && mask.size() == bgr.size())
	{
		cv::Mat red(bgr.size(), CV_8UC3, cv::Scalar(0, 0, 255)), mix;
		cv::addWeighted(bgr, 0.5, red, 0.5, 0, mix);
		mix.copyTo(bgr, mask);
	}
	return mrpt::img::CImage(bgr, mrpt::img::DEEP_COPY);
}
}  // namespace

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
		        "stop after N RGB-D frames (overrides [global] "
		        "max_frames)",
		        false, 0, "N", cmd);
		    TCLAP::SwitchArg aSeg("", "live-segmentation",
		                          "run the segmentation pipeline on the "
		                          "frames as they come",
		                          cmd);
		    TCLAP::ValueArg<std::string> aExp(
		        "c", "config",
		        "experiment .ini for --live-segmentation (default: "
		        "share/bims/default.ini)",
		        false, "", "CONFIG.ini", cmd);
		    TCLAP::SwitchArg aViewer("", "viewer",
		                             "show the RGB frames (with the moving "
		                             "mask) in a window",
		                             cmd);
		    TCLAP::SwitchArg aQuiet("q", "quiet", "no progress lines", cmd);
		    bims::parseCommandLine(
		        cmd, argc, argv,
		        {{"--frames", "--max-frames"}, {"--experiment", "--config"}});
		    bims::checkOutputsSpareInputs({aCfg.getValue(), aExp.getValue()},
		                                  {aOut.getValue()});
		    // Ctrl-C from now on: clean stop
		    const auto& stop = bims::installStopSignals();
		    if (aFrames.getValue() < 0)
			    throw bims::UsageError("--max-frames must be >= 0");
		    // the window before any sensor: no display fails here, before
		    // the IMU is recorded
		    mrpt::gui::CDisplayWindow::Ptr win;
		    if (aViewer.getValue())
		    {
			    const char* display = std::getenv("DISPLAY");
			    if (!display || !*display)
				    throw std::runtime_error(
				        "--viewer needs a display (DISPLAY is not set); "
				        "grab without --viewer, or under X (e.g. xvfb-run)");
			    win = mrpt::gui::CDisplayWindow::Create("bims-grab", 640, 480);
			    if (!win->isOpen())
				    throw std::runtime_error(
				        std::string("--viewer: cannot open a window on "
				                    "display '") +
				        display + "'");
		    }
		    if (!mrpt::system::fileExists(aCfg.getValue()))
			    throw std::runtime_error("cannot open '" + aCfg.getValue() +
			                             "'");

		    bims::checkIniFile(aCfg.getValue());
		    mrpt::config::CConfigFile ini(aCfg.getValue());
		    bims::grab::Grabber grabber(ini);  // throws without devices
		    for (const auto& s : grabber.describe())
			    std::cerr << "bims-grab: " << s << "\n";

		    std::unique_ptr<bims::pipeline::LiveSegmentation> seg;
		    if (aSeg.getValue())
		    {
			    const std::string expIni = aExp.getValue().empty()
			                                   ? bims::defaultExperimentIni()
			                                   : aExp.getValue();
			    bims::pipeline::ExperimentConfig exp;
			    if (!expIni.empty()) exp.loadFromFile(expIni);
			    std::cerr << "bims-grab: live segmentation: "
			              << bims::parametersSource(expIni) << "\n";
			    seg = std::make_unique<bims::pipeline::LiveSegmentation>(
			        exp, "bims-grab", "live input");
		    }
		    bims::RawlogWriter out(aOut.getValue(), 0);  // plain: flushable
		    std::cerr << "bims-grab: writing " << aOut.getValue()
		              << " (Ctrl-C to stop)\n";

		    size_t n = 0;
		    bims::ProgressBar bar("bims-grab",
		                          static_cast<size_t>(aFrames.getValue()),
		                          !aQuiet.getValue());
		    std::string segmented;  ///< the last frame segmented, in words
		    // a frame segmented: its mask in the window
		    auto onSegmented = [&](const bims::source::SourceFrame& f,
		                           const bims::pipeline::FrameResult& r)
		    {
			    if (win && win->isOpen())
				    win->showImage(preview(*f.scan, r.mask));
			    char b[96];
			    std::snprintf(b, sizeof(b), "%zu moving voxels, %.0f ms",
			                  r.movingVoxels, r.ms.total);
			    segmented = b;
		    };
		    auto onFrame =
		        [&](const mrpt::obs::CObservation3DRangeScan::Ptr& scan,
		            const std::vector<mrpt::obs::CObservationIMU::Ptr>& imu)
		    {
			    std::string extra;
			    if (seg)
			    {
				    try
				    {
					    for (const auto& m : imu) seg->push(m, onSegmented);
					    seg->push(scan, onSegmented);
					    extra = segmented;
				    }
				    catch (const std::exception& e)
				    {
					    std::cerr << "bims-grab: segmentation: " << e.what()
					              << "\n";
				    }
			    }
			    else if (win && win->isOpen())
				    win->showImage(preview(*scan, cv::Mat()));
			    bar.update(++n, extra);
		    };

		    const auto st = grabber.run(
		        out, stop, static_cast<size_t>(aFrames.getValue()), onFrame);
		    try
		    {
			    if (seg) seg->finish(onSegmented);  // the frames left
		    }
		    catch (const std::exception& e)
		    {
			    std::cerr << "bims-grab: segmentation: " << e.what() << "\n";
		    }
		    out.close();
		    bar.finish();
		    std::fprintf(stderr,
		                 "bims-grab: %zu RGB-D frames, %zu IMU samples in "
		                 "%.1f s (%s) -> %s\n",
		                 st.frames, st.imu, st.seconds, st.stopReason.c_str(),
		                 aOut.getValue().c_str());
		    const bool clean =
		        st.stopReason == "stopped" || st.stopReason == "max_frames";
		    if (!clean)
			    std::fprintf(
			        stderr,
			        "bims-grab: error: grabbing stopped: %s (the rawlog "
			        "holds everything up to there)\n",
			        st.stopReason.c_str());
		    // The rawlog is closed and everything is printed: leave without
		    // the drivers' destructors. OpenNI2's Dummy driver crashes in its
		    // own thread at shutdown now and then under load (MRPT_NOTES), and
		    // a crash after a complete recording must not turn its exit code
		    // into a failure.
		    std::fflush(nullptr);
		    std::_Exit(clean ? 0 : 1);
		    return 1;  // not reached
	    });
}
