// bims-run: the whole pipeline over rawlogs, driven by one experiment .ini.
//
//   bims-run CONFIG.ini IN.rawlog [MORE.rawlog...] -o OUTDIR [--frames A:B]
//            [--variant bottom-only|flow-only|fused|fused-raycast]
//            [--overwrite] [--quiet]
//   bims-run --print-config [CONFIG.ini]
//
// Writes OUTDIR/trajectory.txt (TUM), masks/NNNNNN.png (255 = moving,
// NNNNNN = 3D-scan index), moving_voxels/NNNNNN.ply, static_map.{ply,bt},
// segmented.rawlog (masks as pixel labels), frames.csv, metrics.json,
// effective.ini (every parameter used), and prints a summary table.
// --print-config prints that effective.ini (of CONFIG.ini, or of the built-in
// defaults) and exits. See docs/pipeline.md and docs/config.md. The run:
// bims::apps::runFromCommandLine (bims/apps/run_command.h).
#include <bims/apps/app.h>
#include <bims/apps/run_command.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

int main(int argc, char** argv)
{
	bims::keepFreedMemoryForReuse();
	return bims::runApp(
	    "bims-run",
	    [&]()
	    {
		    if (const auto rc = bims::apps::printConfigIfAsked(argc, argv))
			    return *rc;
		    TCLAP::CmdLine cmd(
		        "bims: Bayesian independent motion segmentation of RGB-D + IMU "
		        "rawlogs",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> aCfg(
		        "config",
		        "experiment .ini: a file, or a preset of share/bims by name "
		        "(default.ini, paper.ini, bonn.ini, stray.ini, realsense.ini)",
		        true, "", "CONFIG.ini", cmd);
		    TCLAP::UnlabeledMultiArg<std::string> aIn(
		        "rawlogs", "input rawlog(s), read one after the other", true,
		        "IN.rawlog", cmd);
		    TCLAP::ValueArg<std::string> aOut("o", "out", "output folder", true,
		                                      "", "OUTDIR", cmd);
		    TCLAP::ValueArg<std::string> aFrames(
		        "", "frames", "3D-scan indices A:B (inclusive)", false, "",
		        "A:B", cmd);
		    TCLAP::ValueArg<std::string> aVariant(
		        "", "variant",
		        "bottom-only|flow-only|fused|fused-raycast (overrides "
		        "[pipeline] variant)",
		        false, "", "VARIANT", cmd);
		    TCLAP::SwitchArg aOverwrite(
		        "", "overwrite",
		        "replace the outputs of an earlier run in OUTDIR (its files "
		        "only; anything else there stays)",
		        cmd);
		    TCLAP::SwitchArg aQuiet("q", "quiet", "no progress line", cmd);
		    TCLAP::SwitchArg aPrintConfig(
		        "", "print-config",
		        "print every parameter (of CONFIG.ini, or the built-in "
		        "defaults) as .ini and exit: bims-run --print-config "
		        "[CONFIG.ini]",
		        cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    return bims::apps::runFromCommandLine(
		        {aCfg.getValue(), aIn.getValue(), aOut.getValue(),
		         aFrames.getValue(), bims::givenValue(aVariant),
		         aOverwrite.getValue(), !aQuiet.getValue(),
		         // SIGINT / SIGTERM: stop after the current frame, write it
		         // all
		         bims::installStopSignals});
	    });
}
