// bims-viewer: RawLogViewer-style replay of a rawlog with the segmentation
// pipeline running (or a bims-run output folder), 3D view + 2D panels.
//
//   bims-viewer [IN.rawlog] [--results OUTDIR] [--config CONFIG.ini]
//               [--gt groundtruth.txt] [--no-pipeline] [--paused]
//               [--speed S] [--mode realtime|every-frame] [--layers LIST]
//               [--max-frames N --screenshot FILE.png] [--keep-open]
//               [--png-sequence DIR] [--state-file FILE.json]
//
// Non-interactive use (tests, figures): --max-frames N steps N frames, then
// --screenshot writes the 3D view as shown in the window and quits.
#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>
#include <bims/common/share.h>
#include <bims/io/output_paths.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>

#include "viewer_frame.h"

namespace
{
bims::viewer_app::AppOptions gOptions;

class ViewerApp : public wxApp
{
 public:
	bool OnInit() override
	{
		// No wxApp::OnInit(): the command line is ours (parsed in main).
		wxInitAllImageHandlers();
		auto* f = new bims::viewer_app::ViewerFrame(gOptions);
		f->Show(true);
		return true;
	}
};
}  // namespace

wxIMPLEMENT_APP_NO_MAIN(ViewerApp);

int main(int argc, char** argv)
{
	bims::keepFreedMemoryForReuse();
	return bims::runApp(
	    "bims-viewer",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "bims-viewer: replay an RGB-D + IMU rawlog with the motion "
		        "segmentation (3D view: cloud, tier 0 blue, tier 1 yellow, "
		        "tier 2 red, trajectories; 2D panels: RGB + mask, depth, "
		        "observed/expected flow, Diff labels)",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> aIn(
		        "rawlog", "input rawlog (optional: File > Open)", false, "",
		        "IN.rawlog", cmd);
		    TCLAP::ValueArg<std::string> aRes(
		        "", "results",
		        "bims-run output folder: show its trajectory and masks (the "
		        "pipeline is then off unless --run-pipeline)",
		        false, "", "OUTDIR", cmd);
		    TCLAP::ValueArg<std::string> aCfg(
		        "c", "config",
		        "experiment .ini for the pipeline (default: "
		        "share/bims/default.ini)",
		        false, "", "CONFIG.ini", cmd);
		    TCLAP::ValueArg<std::string> aGt(
		        "", "gt",
		        "TUM ground truth (default: <rawlog>_gt/groundtruth.txt)",
		        false, "", "FILE", cmd);
		    TCLAP::SwitchArg aNoPipe(
		        "", "no-pipeline", "replay only, do not run the pipeline", cmd);
		    TCLAP::SwitchArg aRunPipe("", "run-pipeline",
		                              "run the pipeline even with --results",
		                              cmd);
		    TCLAP::SwitchArg aPaused("", "paused", "start paused", cmd);
		    TCLAP::ValueArg<double> aSpeed("", "speed",
		                                   "replay speed (1 = real time)",
		                                   false, 1.0, "S", cmd);
		    TCLAP::ValueArg<std::string> aMode(
		        "", "mode",
		        "playing mode: realtime (the pipeline keeps the data's pace; "
		        "frames finished while the window is still drawing are not "
		        "drawn, all are processed) or every-frame (each frame is "
		        "drawn; playback slows to the drawing)",
		        false, "realtime", "MODE", cmd);
		    TCLAP::ValueArg<std::string> aLayers(
		        "", "layers",
		        "3D layers shown at start, comma-separated: cloud, tier0, "
		        "tier1, tier2, trajectory, gt (or all, none); also in the "
		        "View menu",
		        false, "cloud,tier1,tier2,trajectory,gt", "LIST", cmd);
		    TCLAP::ValueArg<std::string> aState(
		        "", "state-file",
		        "after each frame drawn, write the window's state (frame, "
		        "slider, counter, status bar, widget rectangles) to "
		        "FILE.json (scripts, tests)",
		        false, "", "FILE.json", cmd);
		    TCLAP::ValueArg<int> aFrames("", "max-frames",
		                                 "step N frames at start, then pause",
		                                 false, -1, "N", cmd);
		    TCLAP::ValueArg<std::string> aShot(
		        "", "screenshot",
		        "after --max-frames, write the 3D view to FILE.png and quit",
		        false, "", "FILE.png", cmd);
		    TCLAP::SwitchArg aKeep(
		        "", "keep-open",
		        "stay open after --screenshot (e.g. for an X screenshot of "
		        "the whole window)",
		        cmd);
		    TCLAP::ValueArg<std::string> aSeq(
		        "", "png-sequence",
		        "write the 3D view of every frame shown "
		        "to DIR/NNNNNN.png",
		        false, "", "DIR", cmd);
		    TCLAP::ValueArg<std::string> aSize("", "size", "window size WxH",
		                                       false, "1280x800", "WxH", cmd);
		    bims::parseCommandLine(cmd, argc, argv,
		                           {{"--frames", "--max-frames"}});
		    std::vector<std::string> inputs = {aIn.getValue(), aRes.getValue(),
		                                       aCfg.getValue(), aGt.getValue()};
		    if (aRes.isSet())  // a results folder's files are inputs too
		    {
			    inputs.push_back(aRes.getValue() + "/trajectory.txt");
			    for (auto& f : bims::frameFilesIn(aRes.getValue() + "/masks"))
				    inputs.push_back(std::move(f));
		    }
		    bims::checkOutputsSpareInputs(
		        inputs, bims::givenValues(aShot, aSeq, aState));

		    auto& o = gOptions;
		    // Default parameters: share/bims/default.ini of the build tree or
		    // the install prefix.
		    o.viewer.configPath = aCfg.getValue().empty()
		                              ? bims::defaultExperimentIni()
		                              : aCfg.getValue();
		    o.viewer.rawlog = aIn.getValue();
		    o.viewer.resultsDir = aRes.getValue();
		    o.viewer.groundTruth = aGt.getValue();
		    o.viewer.runPipeline =
		        !aNoPipe.getValue() &&
		        (o.viewer.resultsDir.empty() || aRunPipe.getValue());
		    o.paused = aPaused.getValue();
		    o.speed = aSpeed.getValue();
		    o.frames =
		        aFrames.isSet() ? bims::inRange(aFrames, 0, 100000000) : -1;
		    o.screenshot = aShot.getValue();
		    o.keepOpen = aKeep.getValue();
		    o.pngDir = aSeq.getValue();
		    o.stateFile = aState.getValue();
		    const auto parsed = [](const std::string& flag, auto parse)
		    {
			    try
			    {
				    return parse();
			    }
			    catch (const std::invalid_argument& e)
			    {
				    throw bims::UsageError(flag + ": " + e.what());
			    }
		    };
		    o.mode = parsed(
		        "--mode", [&]
		        { return bims::viewer::playModeFromString(aMode.getValue()); });
		    o.layers = parsed("--layers",
		                      [&] {
			                      return bims::viewer::LayerVisibility::parse(
			                          aLayers.getValue());
		                      });
		    // a PNG sequence holds every frame: each must be drawn
		    if (!o.pngDir.empty()) o.mode = bims::viewer::PlayMode::EveryFrame;
		    if (o.speed <= 0 || !std::isfinite(o.speed))
			    throw bims::UsageError("--speed: a positive number expected");
		    if (std::sscanf(aSize.getValue().c_str(), "%dx%d", &o.width,
		                    &o.height) != 2 ||
		        o.width < 200 || o.height < 150)
			    throw bims::UsageError("--size: expected WxH, e.g. 1280x800");
		    if (!o.screenshot.empty() && o.viewer.rawlog.empty())
			    throw bims::UsageError("--screenshot needs a rawlog");
		    if (!o.viewer.rawlog.empty())  // fail early, before any window
		    {
			    std::ifstream f(o.viewer.rawlog);
			    if (!f)
				    throw std::runtime_error("cannot open rawlog '" +
				                             o.viewer.rawlog + "'");
		    }

		    // the parameters are named only when they are used
		    if (o.viewer.runPipeline)
			    std::cerr << "bims-viewer: "
			              << bims::parametersSource(o.viewer.configPath)
			              << "\n";
		    const char* display = std::getenv("DISPLAY");
		    const char* wayland = std::getenv("WAYLAND_DISPLAY");
		    if ((!display || !*display) && (!wayland || !*wayland))
			    throw std::runtime_error(
			        "no display (DISPLAY is not set). Without a desktop, run "
			        "the viewer under Xvfb, e.g. xvfb-run -a -s '-screen 0 "
			        "1280x900x24 +extension GLX' bims-viewer IN.rawlog "
			        "--max-frames N --screenshot FILE.png");
		    int wxArgc = 1;
		    char* wxArgv[] = {argv[0], nullptr};
		    const int rc = wxEntry(wxArgc, wxArgv);
		    if (!bims::viewer_app::ViewerFrame::created)
			    throw std::runtime_error(
			        std::string("could not open the display '") +
			        (display ? display : wayland) +
			        "' (GTK failed to start; see above). Check DISPLAY, or "
			        "run the viewer under Xvfb: xvfb-run -a bims-viewer ... "
			        "--screenshot FILE.png");
		    if (rc != 0) return rc;
		    return bims::viewer_app::ViewerFrame::exitCode;
	    });
}
