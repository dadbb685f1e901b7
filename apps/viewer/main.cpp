// bims-viewer: RawLogViewer-style replay of a rawlog with the segmentation
// pipeline running (or a bims-run output folder), 3D view + 2D panels.
//
//   bims-viewer [IN.rawlog] [--results OUTDIR] [--config CONFIG.ini]
//               [--gt groundtruth.txt] [--no-pipeline] [--paused]
//               [--speed S] [--max-frames N --screenshot FILE.png]
//               [--keep-open] [--png-sequence DIR]
//
// Non-interactive use (tests, figures): --max-frames N steps N frames, then
// --screenshot writes the 3D view as shown in the window and quits.
#include <bims/common/app.h>
#include <bims/common/output_paths.h>
#include <bims/common/share.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <cstdio>
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
		    bims::checkOutputsSpareInputs({aIn.getValue(), aRes.getValue(),
		                                   aCfg.getValue(), aGt.getValue()},
		                                  bims::givenValues(aShot, aSeq));

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
		    o.frames = aFrames.getValue();
		    o.screenshot = aShot.getValue();
		    o.keepOpen = aKeep.getValue();
		    o.pngDir = aSeq.getValue();
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

		    std::cerr << "bims-viewer: "
		              << bims::parametersSource(o.viewer.configPath) << "\n";
		    int wxArgc = 1;
		    char* wxArgv[] = {argv[0], nullptr};
		    const int rc = wxEntry(wxArgc, wxArgv);
		    if (rc != 0) return rc;
		    return bims::viewer_app::ViewerFrame::exitCode;
	    });
}
