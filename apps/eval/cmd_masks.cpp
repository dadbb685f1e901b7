// bims-eval masks: its command line (the run: bims/apps/eval_run.h).
#include <bims/apps/app.h>
#include <bims/apps/eval_run.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include "commands.h"

int cmdMasks(int argc, char** argv)
{
	TCLAP::CmdLine cmd(
	    "Precision, recall, F1, IoU and the share of static pixels called "
	    "moving of predicted moving-pixel masks (8-bit PNG, 255 = moving, "
	    "NNNNNN.png = 3D scan index) against labels, per frame and in total. "
	    "Labels named NNNNNN.png pair by index; labels named SECONDS.png "
	    "(e.g. a TUM/Bonn folder's depth stamps) pair by time with the run's "
	    "frames.csv. The last line is 'total precision P recall R F1 F IoU "
	    "I'.",
	    ' ', bims::version());
	TCLAP::UnlabeledValueArg<std::string> gtArg(
	    "GT_MASK_DIR", "labels (ground truth)", true, "", "GT_MASK_DIR", cmd);
	TCLAP::UnlabeledValueArg<std::string> predArg(
	    "PRED_MASK_DIR", "predicted masks (bims-run's OUT/masks)", true, "",
	    "PRED_MASK_DIR", cmd);
	TCLAP::ValueArg<std::string> depth(
	    "", "depth-valid",
	    "rawlog whose 3D scans give the valid-depth pixels (and the overlay "
	    "background); without it every pixel counts",
	    false, "", "IN.rawlog", cmd);
	TCLAP::ValueArg<std::string> plotDir(
	    "o", "out",
	    "folder for the per-frame overlays (default: PRED_MASK_DIR_eval)",
	    false, "", "DIR", cmd);
	TCLAP::SwitchArg noPlots("", "no-plots", "do not write overlays", cmd);
	TCLAP::ValueArg<std::string> json(
	    "", "json", "also write per-frame and total figures as JSON", false, "",
	    "FILE", cmd);
	TCLAP::ValueArg<double> voxel(
	    "", "voxel-size",
	    "with --depth-valid: edge of the cubes of the voxel-level figures "
	    "[m] (0 = none)",
	    false, 0.05, "M", cmd);
	TCLAP::ValueArg<int> movingValue(
	    "", "moving-value",
	    "label value meaning moving (labels may hold only the values declared "
	    "here or in the label folder's labels.ini; without either, only 0 "
	    "static and 255 moving: any other value is refused, listing the "
	    "values found)",
	    false, -1, "V", cmd);
	TCLAP::ValueArg<int> staticValue("", "static-value",
	                                 "label value meaning static (default 0 "
	                                 "when values are given)",
	                                 false, -1, "V", cmd);
	TCLAP::ValueArg<std::string> ignoreValues(
	    "", "ignore-values",
	    "label values not scored, e.g. 150,50 (ambiguous, no depth)", false, "",
	    "LIST", cmd);
	TCLAP::ValueArg<std::string> framesCsv(
	    "", "frames-csv",
	    "time stamps of the predictions (columns index, t) when labels are "
	    "named by time (default: frames.csv beside PRED_MASK_DIR)",
	    false, "", "FILE", cmd);
	TCLAP::ValueArg<double> maxDt(
	    "", "max-dt", "largest |t_label - t_prediction| of a pair [s]", false,
	    0.01, "S", cmd);
	TCLAP::SwitchArg sparse(
	    "", "sparse-labels",
	    "labels are a subset of the frames: a prediction inside the labels' "
	    "span (by index or time) without a label is accepted (not scored)",
	    cmd);
	TCLAP::ValueArg<std::string> span(
	    "", "span",
	    "run: score the labels of the run's frames only (a run of --frames "
	    "A:B against a whole recording's labels; the others are left out "
	    "with a note); labels: every label must have a prediction (default: "
	    "run)",
	    false, "run", "run|labels", cmd);
	TCLAP::ValueArg<std::string> strip(
	    "", "strip",
	    "also write the overlays of --strip-frames side by side (half size) "
	    "to this PNG",
	    false, "", "OUT.png", cmd);
	TCLAP::ValueArg<std::string> stripFrames(
	    "", "strip-frames",
	    "comma-separated scan indices of the predictions for --strip", false,
	    "", "i,j,..", cmd);
	TCLAP::SwitchArg overwrite(
	    "", "overwrite",
	    "replace the overlays of an earlier evaluation in the overlay folder "
	    "(its NNNNNN.png files only)",
	    cmd);
	TCLAP::SwitchArg quiet("q", "quiet", "no per-frame lines, no progress",
	                       cmd);
	TCLAP::ValueArg<long> maxSide(
	    "", "image-max-side",
	    "a label or mask declaring more pixels per side is refused before "
	    "it is decoded (as [input] image_max_side)",
	    false, bims::kMaxImageSide, "N", cmd);
	TCLAP::ValueArg<long> maxPixels(
	    "", "image-max-pixels",
	    "a label or mask declaring more pixels (width x height) is refused "
	    "before it is decoded (as [input] image_max_pixels)",
	    false, static_cast<long>(bims::kMaxImagePixels), "N", cmd);
	bims::parseCommandLine(cmd, argc, argv, {{"--plot-dir", "--out"}});
	bims::apps::EvalMasksOptions o;
	o.gtDir = gtArg.getValue();
	o.predDir = predArg.getValue();
	o.depthValid = bims::givenValue(depth);
	o.overlayDir = bims::givenValue(plotDir);
	o.noPlots = noPlots.getValue();
	o.json = bims::givenValue(json);
	o.voxelSize = voxel.getValue();
	o.movingValue = bims::givenValue(movingValue);
	o.staticValue = bims::givenValue(staticValue);
	o.ignoreValues = bims::givenValue(ignoreValues);
	o.framesCsv = bims::givenValue(framesCsv);
	o.maxDt = maxDt.getValue();
	o.sparseLabels = sparse.getValue();
	o.span = span.getValue();
	o.strip = bims::givenValue(strip);
	o.stripFrames = stripFrames.getValue();
	o.overwrite = overwrite.getValue();
	o.quiet = quiet.getValue();
	bims::inRange(maxSide, 1L, bims::ImageLimits::kSideAtMost);
	bims::inRange(maxPixels, 1L, bims::ImageLimits::kPixelsAtMost);
	o.images = {maxSide.getValue(), maxPixels.getValue(),
	            "--image-max-side, --image-max-pixels"};
	return bims::apps::runEvalMasks(o);
}
