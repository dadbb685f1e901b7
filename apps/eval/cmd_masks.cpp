#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>
#include <bims/apps/progress_bar.h>
#include <bims/common/frame_files.h>
#include <bims/common/json.h>
#include <bims/common/output_paths.h>
#include <bims/common/rawlog.h>
#include <bims/eval/depth_consistency.h>
#include <bims/eval/mask_labels.h>
#include <bims/eval/mask_metrics.h>
#include <bims/eval/plots.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "commands.h"

namespace ev = bims::eval;
namespace fs = std::filesystem;

namespace
{
/** Streams the 3D scans of a rawlog by their index (from 0). */
class ScanStream
{
 public:
	explicit ScanStream(const std::string& path) : r_(path) {}
	/** The scan with index \a k (k must not decrease between calls). */
	mrpt::obs::CObservation3DRangeScan::Ptr get(long k)
	{
		while (n_ <= k)
		{
			auto o = r_.next();
			if (!o)
				throw std::runtime_error(
				    r_.path() + ": has only " + std::to_string(n_) +
				    " 3D scans; mask " + std::to_string(k) + " needs scan " +
				    std::to_string(k) + " (counted from 0)");
			if (auto s = std::dynamic_pointer_cast<
			        mrpt::obs::CObservation3DRangeScan>(o))
			{
				cur_ = s;
				n_++;
			}
		}
		return cur_;
	}

 private:
	bims::RawlogReader r_;
	long n_ = 0;
	mrpt::obs::CObservation3DRangeScan::Ptr cur_;
};

/** "000042" for scan 42 (the stem of its frame files). */
std::string frameName(long k)
{
	std::string s = bims::frameFileName(k);
	return s.erase(s.rfind('.'));
}
}  // namespace

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
	    "label value meaning moving (with it, or with --static-value or "
	    "--ignore-values, labels may hold only the values given; default: "
	    ">= 128 is moving)",
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
	    "time span without a label is accepted (not scored)",
	    cmd);
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
	bims::parseCommandLine(cmd, argc, argv, {{"--plot-dir", "--out"}});
	std::vector<std::string> inputs = {gtArg.getValue(), predArg.getValue(),
	                                   depth.getValue(), framesCsv.getValue()};
	// the masks in the two folders are inputs too (--json PRED/000000.png)
	for (const std::string& dir : {gtArg.getValue(), predArg.getValue()})
		for (auto& f : bims::frameFilesIn(dir)) inputs.push_back(std::move(f));
	bims::checkOutputsSpareInputs(inputs,
	                              bims::givenValues(plotDir, json, strip));

	if (voxel.getValue() < 0 || !std::isfinite(voxel.getValue()))
		throw bims::UsageError("--voxel-size must be >= 0");
	const auto stripSet =
	    bims::parseIndexList(stripFrames.getValue(), "--strip-frames");
	if (strip.isSet() != !stripSet.empty())
		throw bims::UsageError("--strip and --strip-frames go together");
	if (!(maxDt.getValue() > 0) || !std::isfinite(maxDt.getValue()))
		throw bims::UsageError("--max-dt must be > 0");
	ev::LabelConvention labels;
	if (movingValue.isSet() || staticValue.isSet() || ignoreValues.isSet())
	{
		try
		{
			labels = ev::LabelConvention::explicitValues(
			    movingValue.getValue(), staticValue.getValue(),
			    ev::parseLabelValues(ignoreValues.getValue()));
		}
		catch (const std::invalid_argument& e)
		{
			throw bims::UsageError(std::string("label values: ") + e.what());
		}
	}
	const std::string gtDir = gtArg.getValue(), predDir = predArg.getValue();
	const auto gtFiles = ev::listMaskFiles(gtDir);
	const auto predFiles = ev::listMaskFiles(predDir);
	std::string p = predDir;
	while (p.size() > 1 && p.back() == '/') p.pop_back();
	std::map<long, double> stamps;
	if (gtFiles.front().byTime() && !predFiles.front().byTime())
	{
		const std::string csv =
		    framesCsv.isSet()
		        ? framesCsv.getValue()
		        : (fs::path(p).parent_path() / "frames.csv").string();
		if (!framesCsv.isSet() && !fs::exists(csv))
			throw std::runtime_error(
			    gtDir + ": labels are named by time and " + predDir +
			    " by scan index: their stamps are in the run's frames.csv, not "
			    "found at " +
			    csv + " (give --frames-csv)");
		stamps = ev::readFrameStamps(csv);
	}
	const ev::MaskMatch match =
	    ev::matchMasks(gtFiles, predFiles, stamps, maxDt.getValue());
	const size_t nLabels = gtFiles.size(), nPairs = match.pairs.size();
	if (nPairs == 0)
		throw std::runtime_error(
		    predDir + ": none of the " + std::to_string(nLabels) +
		    " labels of " + gtDir + " has a prediction" +
		    (gtFiles.front().byTime()
		         ? " within " + std::to_string(maxDt.getValue()) + " s"
		         : std::string(" of its name")));
	if (gtFiles.front().byTime() && 2 * nPairs < nLabels)
		throw std::runtime_error(
		    predDir + ": only " + std::to_string(nPairs) + " of the " +
		    std::to_string(nLabels) + " labels of " + gtDir +
		    " have a prediction within " + std::to_string(maxDt.getValue()) +
		    " s: the predictions are not of these frames (another run?)");
	if (!match.predictionsWithoutLabel.empty() && !sparse.getValue())
	{
		const ev::MaskFile* f = match.predictionsWithoutLabel.front();
		throw std::runtime_error(
		    gtDir + ": no label within " + std::to_string(maxDt.getValue()) +
		    " s of prediction " + f->name +
		    (f->byTime() ? std::string()
		                 : " (t " + std::to_string(stamps.at(f->index)) + ")") +
		    ", inside the labels' time span (" +
		    std::to_string(match.predictionsWithoutLabel.size()) +
		    " such): a missing label frame? (--sparse-labels if the labels "
		    "are a subset)");
	}
	if (depth.isSet() && predFiles.front().byTime())
		throw bims::UsageError(
		    "--depth-valid needs predictions named by scan index");

	std::string outDir;
	if (!noPlots.getValue())
	{
		outDir = plotDir.isSet() ? plotDir.getValue() : p + "_eval";
		bims::checkOutputsSpareInputs(inputs, {outDir});
		// the overlays: one PNG per prediction, named as it is
		bims::prepareOutputFolder(outDir, {{}, {{"", ".png"}}},
		                          overwrite.getValue());
		bims::makeDirs(outDir);
	}
	std::unique_ptr<ScanStream> scans;
	if (depth.isSet()) scans = std::make_unique<ScanStream>(depth.getValue());

	ev::MaskMetrics total, totalVoxels, peopleFree;
	size_t nPeopleFree = 0;
	std::map<long, cv::Mat> tiles;  // for --strip
	bims::Json jsonFrames = bims::Json::array();
	bims::ProgressBar bar("bims-eval masks", match.pairs.size(),
	                      !quiet.getValue());
	size_t done = 0;
	for (const ev::MaskPair& pair : match.pairs)
	{
		bar.update(done++);  // the pairs scored before this one
		const ev::MaskFile& f = *pair.pred;
		const std::string predPath = predDir + "/" + f.name;
		const std::string gtPath = gtDir + "/" + pair.label->name;
		const std::string frame = f.byTime()
		                              ? f.name.substr(0, f.name.size() - 4)
		                              : frameName(f.index);
		const cv::Mat g = ev::loadMask(gtPath), pm = ev::loadMask(predPath);
		cv::Mat valid, background, depthM;
		mrpt::img::TCamera cam;
		if (scans)
		{
			auto s = scans->get(f.index);
			s->load();
			const cv::Mat d = ev::depthFromObservation(*s);
			depthM = d;
			cam = s->cameraParams;
			valid = d > 0;
			if (s->hasIntensityImage && !s->intensityImage.isEmpty())
				background =
				    s->intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY);
			if (valid.size() != g.size())
				throw std::runtime_error(
				    depth.getValue() + ": scan " + std::to_string(f.index) +
				    " is " + std::to_string(valid.cols) + "x" +
				    std::to_string(valid.rows) + " but " + gtPath + " is " +
				    std::to_string(g.cols) + "x" + std::to_string(g.rows));
			if (background.size() != g.size()) background = cv::Mat();
		}
		ev::MaskMetrics m;
		// the labels in the contract's terms, for the voxel figures and the
		// overlay (not-scored pixels drawn and binned as without depth)
		cv::Mat gMoving = g, scored;
		try
		{
			m.accumulate(g, pm, valid, labels);
			if (!labels.isContract())
			{
				labels.toContract(g, gMoving, scored);
				valid = valid.empty() ? scored : (valid & scored);
				if (!depthM.empty()) depthM.setTo(0, scored == 0);
			}
			if (!depthM.empty() && voxel.getValue() > 0)
				totalVoxels += ev::voxelMaskMetrics(
				    gMoving, pm, depthM, cam.fx(), cam.fy(), cam.cx(), cam.cy(),
				    voxel.getValue());
		}
		catch (const std::invalid_argument& e)
		{
			throw std::runtime_error(gtPath + " vs " + predPath + ": " +
			                         e.what());
		}
		total += m;
		if (m.tp + m.fn == 0)
		{
			// no moving label in the frame: every call of moving is false
			peopleFree += m;
			++nPeopleFree;
		}
		const std::string line = "frame " + frame + " tp " +
		                         std::to_string(m.tp) + " fp " +
		                         std::to_string(m.fp) + " fn " +
		                         std::to_string(m.fn) + " " + m.scoresLine();
		if (!quiet.getValue()) std::printf("%s\n", line.c_str());
		const bool inStrip = stripSet.count(static_cast<size_t>(f.index)) > 0;
		if (!outDir.empty() || inStrip)
		{
			const cv::Mat o =
			    ev::maskOverlay(gMoving, pm, valid, background,
			                    "frame " + frame + "  " + m.scoresLine());
			if (!outDir.empty()) ev::writePng(outDir + "/" + f.name, o);
			if (inStrip) tiles[f.index] = o;
		}
		jsonFrames.push_back(
		    {{"frame", f.byTime() ? bims::Json(frame) : bims::Json(f.index)},
		     {"label", pair.label->name},
		     {"dt", bims::jsonNumber(pair.dt, 6)},
		     {"metrics", m.toJson()}});
	}
	bar.finish();
	if (!match.labelsWithoutPrediction.empty())
		std::fprintf(
		    stderr,
		    "bims-eval masks: warning: %zu of %zu labels have no prediction in "
		    "%s (not counted; first: %s)\n",
		    match.labelsWithoutPrediction.size(), nLabels, predDir.c_str(),
		    match.labelsWithoutPrediction.front()->name.c_str());
	if (match.predictionsOutside > 0 || !match.predictionsWithoutLabel.empty())
		std::fprintf(stderr,
		             "bims-eval masks: %zu predictions without a label (%d "
		             "outside the labels' time span), not scored\n",
		             match.predictionsWithoutLabel.size() +
		                 size_t(match.predictionsOutside),
		             match.predictionsOutside);
	if (strip.isSet())
	{
		if (tiles.size() != stripSet.size())
			throw std::runtime_error(
			    "--strip-frames: " +
			    std::to_string(stripSet.size() - tiles.size()) +
			    " of the frames have no label and prediction pair");
		std::vector<cv::Mat> row;
		for (auto& [k, t] : tiles) row.push_back(t);
		ev::writePng(strip.getValue(), ev::imageStrip(row, 0.5));
		std::fprintf(stderr, "bims-eval masks: strip of %zu frames in %s\n",
		             row.size(), strip.getValue().c_str());
	}
	if (!outDir.empty())
		std::fprintf(
		    stderr,
		    "bims-eval masks: overlays (TP green, FP red, FN blue) in %s\n",
		    outDir.c_str());
	const bool voxels = scans && voxel.getValue() > 0;
	if (voxels)
		std::printf(
		    "voxel_total voxel %.3f m (camera-frame cubes, majority "
		    "of their pixels): %s\n",
		    voxel.getValue(), totalVoxels.scoresLine().c_str());
	else
		std::fprintf(stderr,
		             "bims-eval masks: voxel-level figures need --depth-valid "
		             "and --voxel-size > 0\n");
	if (json.isSet())
	{
		bims::Json jf;
		jf["gt"] = gtDir;
		jf["pred"] = predDir;
		jf["labels"] = labels.describe();
		jf["frames_compared"] = nPairs;
		jf["frames_missing"] = match.labelsWithoutPrediction.size();
		jf["depth_valid_only"] = bool(scans);
		jf["total"] = total.toJson();
		jf["frames_nothing_moving"] = nPeopleFree;
		jf["total_nothing_moving"] = peopleFree.toJson();
		if (voxels)
		{
			jf["voxel_size_m"] = voxel.getValue();
			jf["total_voxels"] = totalVoxels.toJson();
		}
		jf["frames"] = std::move(jsonFrames);
		bims::writeJsonFile(json.getValue(), jf);
	}
	std::printf(
	    "total_counts frames %zu tp %llu fp %llu fn %llu tn %llu invalid "
	    "%llu ignored %llu\n",
	    nPairs, static_cast<unsigned long long>(total.tp),
	    static_cast<unsigned long long>(total.fp),
	    static_cast<unsigned long long>(total.fn),
	    static_cast<unsigned long long>(total.tn),
	    static_cast<unsigned long long>(total.invalid),
	    static_cast<unsigned long long>(total.ignored));
	std::printf(
	    "total_static_as_moving %.4f (labelled-static pixels called "
	    "moving)\n",
	    total.staticAsMoving());
	std::printf(
	    "total_nothing_moving frames %zu static_as_moving %.4f "
	    "(frames without a moving label)\n",
	    nPeopleFree, peopleFree.staticAsMoving());
	std::printf("total %s\n", total.scoresLine().c_str());
	return 0;
}
