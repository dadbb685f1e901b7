// bims-eval masks (eval_run.h), in its steps: the inputs and the options'
// checks, the label convention, the pairing of labels with predictions,
// the overlay folder, each pair scored, then the warnings, the strip, the
// JSON and the totals.
#include <bims/apps/app.h>
#include <bims/apps/eval_run.h>
#include <bims/apps/output_checks.h>
#include <bims/apps/progress_bar.h>
#include <bims/eval/depth_consistency.h>
#include <bims/eval/mask_labels.h>
#include <bims/eval/mask_metrics.h>
#include <bims/eval/plots.h>
#include <bims/io/frame_files.h>
#include <bims/io/json.h>
#include <bims/io/output_paths.h>
#include <bims/io/rawlog.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>

namespace bims::apps
{
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
	RawlogReader r_;
	long n_ = 0;
	mrpt::obs::CObservation3DRangeScan::Ptr cur_;
};

/** "000042" for scan 42 (the stem of its frame files). */
std::string frameName(long k)
{
	std::string s = frameFileName(k);
	return s.erase(s.rfind('.'));
}

/** Every file the evaluation reads: the two folders and the masks in
 * them (--json PRED/000000.png is refused), the rawlog and the CSV. */
std::vector<std::string> masksInputs(const EvalMasksOptions& o)
{
	std::vector<std::string> inputs = {o.gtDir, o.predDir,
	                                   o.depthValid.value_or(""),
	                                   o.framesCsv.value_or("")};
	for (const std::string& dir : {o.gtDir, o.predDir})
		for (auto& f : frameFilesIn(dir)) inputs.push_back(std::move(f));
	return inputs;
}

/** The checks of the options alone (UsageError); the frames of the
 * strip. */
std::set<size_t> checkMasksOptions(const EvalMasksOptions& o,
                                   const std::vector<std::string>& inputs)
{
	std::vector<std::string> outputs;
	for (const auto* out : {&o.overlayDir, &o.json, &o.strip})
		if (*out) outputs.push_back(**out);
	checkOutputsSpareInputs(inputs, outputs);
	if (o.voxelSize < 0 || !std::isfinite(o.voxelSize))
		throw UsageError("--voxel-size must be >= 0");
	const auto stripSet = parseIndexList(o.stripFrames, "--strip-frames");
	if (o.strip.has_value() != !stripSet.empty())
		throw UsageError("--strip and --strip-frames go together");
	if (!(o.maxDt > 0) || !std::isfinite(o.maxDt))
		throw UsageError("--max-dt must be > 0");
	if (o.span != "run" && o.span != "labels")
		throw UsageError("--span is run or labels, not '" + o.span + "'");
	return stripSet;
}

/** The labels' values and where they were declared: the options, else
 * the label folder's labels.ini, else bims's own 0 static and 255 moving
 * (what bims-sim and bims-run write); any other value is refused by
 * checkLabelValues, never guessed. */
struct DeclaredLabels
{
	ev::LabelConvention convention;
	std::string source;  ///< "the options", the labels.ini, "bims's own"
};

DeclaredLabels labelConvention(const EvalMasksOptions& o)
{
	DeclaredLabels d;
	if (o.movingValue || o.staticValue || o.ignoreValues)
	{
		try
		{
			d.convention = ev::LabelConvention::explicitValues(
			    o.movingValue.value_or(-1), o.staticValue.value_or(-1),
			    ev::parseLabelValues(o.ignoreValues.value_or("")));
		}
		catch (const std::invalid_argument& e)
		{
			throw UsageError(std::string("label values: ") + e.what());
		}
		d.source = "the options";
		return d;
	}
	if (auto c = ev::readLabelConventionFile(o.gtDir))
	{
		d.convention = *c;
		d.source = (fs::path(o.gtDir) / ev::kLabelConventionFile).string();
		return d;
	}
	d.convention = ev::LabelConvention::explicitValues(255, 0, {});
	d.source = "bims's own, no other declared";
	return d;
}

/** Every value of the paired labels known to the convention, before any
 * output: else a usage error listing the values found, their counts and
 * how to declare them. */
void checkLabelValues(const EvalMasksOptions& o, const ev::MaskMatch& match,
                      const DeclaredLabels& labels)
{
	ev::LabelValueCounts counts;
	for (const ev::MaskPair& pair : match.pairs)
		counts.add(ev::loadMask(o.gtDir + "/" + pair.label->name, o.images));
	const std::vector<int> unknown = counts.unknown(labels.convention);
	if (unknown.empty()) return;
	std::string values;
	for (int v : unknown)
		values += (values.empty() ? "" : ",") + std::to_string(v) +
		          " (first in " +
		          match.pairs[counts.firstImage[v]].label->name + ")";
	throw UsageError(
	    o.gtDir + ": label values " + values + " are neither moving, static " +
	    "nor not scored under " + labels.convention.describe() + " (" +
	    labels.source + "); a value is never guessed. The values found: " +
	    counts.describe(labels.convention) +
	    ". Declare every value: --moving-value V --static-value V "
	    "--ignore-values LIST (e.g. --moving-value 255 --static-value 0 "
	    "--ignore-values 150,50 for the Bonn and Stray labels of the shared "
	    "data), or a " +
	    ev::kLabelConventionFile + " in " + o.gtDir +
	    " ([labels] moving = 255, static = 0, not_scored = 150 50)");
}

/** The labels and predictions and which pairs with which (by index, or by
 * time through the run's frames.csv). \a match points into the lists. */
struct MaskPairing
{
	std::vector<ev::MaskFile> gtFiles, predFiles;
	std::map<long, double> stamps;  ///< the predictions' (by time only)
	ev::MaskMatch match;
};

/** The predictions' folder without its trailing '/'. */
std::string trimmedDir(std::string p)
{
	while (p.size() > 1 && p.back() == '/') p.pop_back();
	return p;
}

/** Pairs the labels with the predictions; throws when too few pair (other
 * frames than the labels'), or a prediction inside the labels' span has
 * no label (unless sparse). */
std::unique_ptr<MaskPairing> pairMasks(const EvalMasksOptions& o)
{
	auto pm = std::make_unique<MaskPairing>();
	MaskPairing& p = *pm;
	const std::string &gtDir = o.gtDir, &predDir = o.predDir;
	p.gtFiles = ev::listMaskFiles(gtDir);
	p.predFiles = ev::listMaskFiles(predDir);
	if (p.gtFiles.front().byTime() && !p.predFiles.front().byTime())
	{
		const std::string csv =
		    o.framesCsv
		        ? *o.framesCsv
		        : (fs::path(trimmedDir(predDir)).parent_path() / "frames.csv")
		              .string();
		if (!o.framesCsv && !fs::exists(csv))
			throw std::runtime_error(
			    gtDir + ": labels are named by time and " + predDir +
			    " by scan index: their stamps are in the run's frames.csv, not "
			    "found at " +
			    csv + " (give --frames-csv)");
		p.stamps = ev::readFrameStamps(csv);
	}
	p.match = ev::matchMasks(p.gtFiles, p.predFiles, p.stamps, o.maxDt);
	if (o.span == "labels") p.match.labelsOutsidePredictions.clear();
	// the labels of the run's frames (--span run) or all of them
	const size_t nLabels =
	    p.gtFiles.size() - p.match.labelsOutsidePredictions.size();
	const size_t nPairs = p.match.pairs.size();
	if (nPairs == 0)
		throw std::runtime_error(
		    predDir + ": none of the " + std::to_string(nLabels) +
		    " labels of " + gtDir + " has a prediction" +
		    (p.gtFiles.front().byTime()
		         ? " within " + std::to_string(o.maxDt) + " s"
		         : std::string(" of its name")));
	if (p.gtFiles.front().byTime() && 2 * nPairs < nLabels)
		throw std::runtime_error(
		    predDir + ": only " + std::to_string(nPairs) + " of the " +
		    std::to_string(nLabels) + " labels of " + gtDir +
		    (o.span == "run" ? " inside the run's span" : "") +
		    " have a prediction within " + std::to_string(o.maxDt) +
		    " s: the predictions are not of these frames (another run?)");
	if (!p.match.predictionsWithoutLabel.empty() && !o.sparseLabels &&
	    !p.gtFiles.front().byTime())
	{
		// by index: the labels missing, as named
		const auto& missing = p.match.predictionsWithoutLabel;
		std::string names;
		for (size_t k = 0; k < missing.size() && k < 5; ++k)
			names += (k ? ", " : "") + missing[k]->name;
		if (missing.size() > 5) names += ", ...";
		throw std::runtime_error(
		    gtDir + ": no label of the same name for " +
		    std::to_string(missing.size()) + " prediction(s) of " + predDir +
		    " inside the labels' span (" + p.gtFiles.front().name + " to " +
		    p.gtFiles.back().name + "): " + names +
		    ": missing label frames? (--sparse-labels if the labels are a "
		    "subset)");
	}
	if (!p.match.predictionsWithoutLabel.empty() && !o.sparseLabels)
	{
		const ev::MaskFile* f = p.match.predictionsWithoutLabel.front();
		throw std::runtime_error(
		    gtDir + ": no label within " + std::to_string(o.maxDt) +
		    " s of prediction " + f->name +
		    (f->byTime()
		         ? std::string()
		         : " (t " + std::to_string(p.stamps.at(f->index)) + ")") +
		    ", inside the labels' time span (" +
		    std::to_string(p.match.predictionsWithoutLabel.size()) +
		    " such): a missing label frame? (--sparse-labels if the labels "
		    "are a subset)");
	}
	if (o.depthValid && p.predFiles.front().byTime())
		throw UsageError("--depth-valid needs predictions named by scan index");
	return pm;
}

/** The overlay folder, checked, an earlier evaluation's overlays refused
 * or removed (--overwrite), created; "" with --no-plots. */
std::string prepareOverlayFolder(const EvalMasksOptions& o,
                                 const std::vector<std::string>& inputs)
{
	if (o.noPlots) return "";
	const std::string outDir =
	    o.overlayDir ? *o.overlayDir : trimmedDir(o.predDir) + "_eval";
	checkOutputsSpareInputs(inputs, {outDir});
	// the overlays: one PNG per prediction, named as it is
	prepareOutputFolder(outDir, {{}, {{"", ".png"}}}, o.overwrite);
	makeDirs(outDir);
	return outDir;
}

/** What the scored pairs add up to. */
struct MaskTotals
{
	ev::MaskMetrics total, totalVoxels, peopleFree;
	size_t nPeopleFree = 0;         ///< frames without a moving label
	std::map<long, cv::Mat> tiles;  ///< overlays of the strip's frames
	Json jsonFrames = Json::array();
};

/** One frame's depth, when a rawlog gives it: its valid pixels, its
 * metric depth, its camera and its image (the overlay's background). */
struct FrameDepth
{
	cv::Mat valid, background, depthM;
	mrpt::img::TCamera cam;
};

/** Scan \a f.index of \a scans, checked to be of the label's size. */
FrameDepth frameDepth(ScanStream& scans, const ev::MaskFile& f,
                      const std::string& rawlog, const std::string& gtPath,
                      const cv::Mat& g)
{
	FrameDepth d;
	auto s = scans.get(f.index);
	s->load();
	const cv::Mat depth = ev::depthFromObservation(*s);
	d.depthM = depth;
	d.cam = s->cameraParams;
	d.valid = depth > 0;
	if (s->hasIntensityImage && !s->intensityImage.isEmpty())
		d.background =
		    s->intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY);
	if (d.valid.size() != g.size())
		throw std::runtime_error(rawlog + ": scan " + std::to_string(f.index) +
		                         " is " + std::to_string(d.valid.cols) + "x" +
		                         std::to_string(d.valid.rows) + " but " +
		                         gtPath + " is " + std::to_string(g.cols) +
		                         "x" + std::to_string(g.rows));
	if (d.background.size() != g.size()) d.background = cv::Mat();
	return d;
}

/** Scores one pair: its line on stdout (unless quiet), its overlay (in
 * \a overlays' folder, and kept for the strip), its JSON record; adds it to \a
 * t. */
void scorePair(const EvalMasksOptions& o, const ev::MaskPair& pair,
               const ev::LabelConvention& labels, ScanStream* scans,
               OutputManifest* overlays, const std::set<size_t>& stripSet,
               MaskTotals& t)
{
	const ev::MaskFile& f = *pair.pred;
	const std::string predPath = o.predDir + "/" + f.name;
	const std::string gtPath = o.gtDir + "/" + pair.label->name;
	const std::string frame =
	    f.byTime() ? f.name.substr(0, f.name.size() - 4) : frameName(f.index);
	const cv::Mat g = ev::loadMask(gtPath, o.images),
	              pm = ev::loadMask(predPath, o.images);
	FrameDepth d;
	if (scans) d = frameDepth(*scans, f, *o.depthValid, gtPath, g);
	ev::MaskMetrics m;
	// the labels in the contract's terms, for the voxel figures and the
	// overlay (not-scored pixels drawn and binned as without depth)
	cv::Mat gMoving = g, scored;
	try
	{
		m.accumulate(g, pm, d.valid, labels);
		if (!labels.isContract())
		{
			labels.toContract(g, gMoving, scored);
			d.valid = d.valid.empty() ? scored : (d.valid & scored);
			if (!d.depthM.empty()) d.depthM.setTo(0, scored == 0);
		}
		if (!d.depthM.empty() && o.voxelSize > 0)
			t.totalVoxels += ev::voxelMaskMetrics(
			    gMoving, pm, d.depthM, d.cam.fx(), d.cam.fy(), d.cam.cx(),
			    d.cam.cy(), o.voxelSize);
	}
	catch (const std::invalid_argument& e)
	{
		throw std::runtime_error(gtPath + " vs " + predPath + ": " + e.what());
	}
	t.total += m;
	if (m.tp + m.fn == 0)
	{
		// no moving label in the frame: every call of moving is false
		t.peopleFree += m;
		++t.nPeopleFree;
	}
	const std::string line = "frame " + frame + " tp " + std::to_string(m.tp) +
	                         " fp " + std::to_string(m.fp) + " fn " +
	                         std::to_string(m.fn) + " " + m.frameScoresLine();
	if (!o.quiet) std::printf("%s\n", line.c_str());
	const bool inStrip = stripSet.count(static_cast<size_t>(f.index)) > 0;
	if (overlays || inStrip)
	{
		const cv::Mat overlay =
		    ev::maskOverlay(gMoving, pm, d.valid, d.background,
		                    "frame " + frame + "  " + m.frameScoresLine());
		if (overlays) ev::writePng(overlays->file(f.name), overlay);
		if (inStrip) t.tiles[f.index] = overlay;
	}
	t.jsonFrames.push_back({{"frame", f.byTime() ? Json(frame) : Json(f.index)},
	                        {"label", pair.label->name},
	                        {"dt", jsonNumber(pair.dt, 6)},
	                        {"metrics", m.toJson()}});
}

/** The labels without a prediction of the run's frames (those outside,
 * with --span run, in a note), the predictions without a label. */
void printUnpaired(const EvalMasksOptions& o, const MaskPairing& p)
{
	const ev::MaskMatch& match = p.match;
	const auto& outside = match.labelsOutsidePredictions;
	std::vector<const ev::MaskFile*> inside;
	for (const ev::MaskFile* f : match.labelsWithoutPrediction)
		if (std::find(outside.begin(), outside.end(), f) == outside.end())
			inside.push_back(f);
	if (!outside.empty())
		std::fprintf(stderr,
		             "bims-eval masks: note: %zu of %zu labels lie outside the "
		             "run's frames (%s to %s), not scored: the run covers "
		             "part of the labelled frames (--span run; --span labels "
		             "requires a prediction for every label)\n",
		             outside.size(), p.gtFiles.size(),
		             p.match.pairs.front().label->name.c_str(),
		             p.match.pairs.back().label->name.c_str());
	if (!inside.empty())
		std::fprintf(
		    stderr,
		    "bims-eval masks: warning: %zu of %zu labels have no prediction in "
		    "%s (not counted; first: %s)\n",
		    inside.size(), p.gtFiles.size() - outside.size(), o.predDir.c_str(),
		    inside.front()->name.c_str());
	if (match.predictionsOutside > 0 || !match.predictionsWithoutLabel.empty())
		std::fprintf(stderr,
		             "bims-eval masks: %zu predictions without a label (%d "
		             "outside the labels' span), not scored\n",
		             match.predictionsWithoutLabel.size() +
		                 size_t(match.predictionsOutside),
		             match.predictionsOutside);
}

/** --strip: the strip frames' overlays side by side, half size. */
void writeStrip(const std::string& path, const std::set<size_t>& stripSet,
                const MaskTotals& t)
{
	if (t.tiles.size() != stripSet.size())
		throw std::runtime_error(
		    "--strip-frames: " +
		    std::to_string(stripSet.size() - t.tiles.size()) +
		    " of the frames have no label and prediction pair");
	std::vector<cv::Mat> row;
	for (auto& [k, tile] : t.tiles) row.push_back(tile);
	ev::writePng(path, ev::imageStrip(row, 0.5));
	std::fprintf(stderr, "bims-eval masks: strip of %zu frames in %s\n",
	             row.size(), path.c_str());
}

/** --json: the options' figures, the totals and every frame's record. */
void writeMasksJson(const EvalMasksOptions& o, const MaskPairing& p,
                    const ev::LabelConvention& labels, bool depthValidOnly,
                    bool voxels, MaskTotals& t)
{
	Json jf;
	jf["gt"] = o.gtDir;
	jf["pred"] = o.predDir;
	jf["labels"] = labels.describe();
	jf["frames_compared"] = p.match.pairs.size();
	jf["frames_missing"] = p.match.labelsWithoutPrediction.size() -
	                       p.match.labelsOutsidePredictions.size();
	jf["labels_outside_run"] = p.match.labelsOutsidePredictions.size();
	jf["depth_valid_only"] = depthValidOnly;
	jf["total"] = t.total.toJson();
	jf["frames_nothing_moving"] = t.nPeopleFree;
	jf["total_nothing_moving"] = t.peopleFree.toJson();
	if (voxels)
	{
		jf["voxel_size_m"] = o.voxelSize;
		jf["total_voxels"] = t.totalVoxels.toJson();
	}
	jf["frames"] = std::move(t.jsonFrames);
	writeJsonFile(*o.json, jf);
}

/** The totals' lines on stdout (the last: "total precision P ..."). */
void printTotals(size_t nPairs, const MaskTotals& t)
{
	const ev::MaskMetrics& total = t.total;
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
	    t.nPeopleFree, t.peopleFree.staticAsMoving());
	std::printf("total %s\n", total.scoresLine().c_str());
}
}  // namespace

int runEvalMasks(const EvalMasksOptions& o)
{
	const std::vector<std::string> inputs = masksInputs(o);
	const std::set<size_t> stripSet = checkMasksOptions(o, inputs);
	const DeclaredLabels declared = labelConvention(o);
	const ev::LabelConvention& labels = declared.convention;
	const auto pairing = pairMasks(o);
	checkLabelValues(o, pairing->match, declared);
	if (!o.quiet)
		std::fprintf(stderr, "bims-eval masks: labels: %s (%s)\n",
		             labels.describe().c_str(), declared.source.c_str());
	const std::string outDir = prepareOverlayFolder(o, inputs);
	std::unique_ptr<OutputManifest> overlays;
	if (!outDir.empty())
		overlays = std::make_unique<OutputManifest>(outDir, "bims-eval masks");
	std::unique_ptr<ScanStream> scans;
	if (o.depthValid) scans = std::make_unique<ScanStream>(*o.depthValid);

	MaskTotals t;
	const auto& pairs = pairing->match.pairs;
	ProgressBar bar("bims-eval masks", pairs.size(), !o.quiet);
	size_t done = 0;
	for (const ev::MaskPair& pair : pairs)
	{
		bar.update(done++);  // the pairs scored before this one
		scorePair(o, pair, labels, scans.get(), overlays.get(), stripSet, t);
	}
	bar.finish();
	printUnpaired(o, *pairing);
	if (o.strip) writeStrip(*o.strip, stripSet, t);
	if (!outDir.empty())
		std::fprintf(
		    stderr,
		    "bims-eval masks: overlays (TP green, FP red, FN blue) in %s\n",
		    outDir.c_str());
	const bool voxels = scans && o.voxelSize > 0;
	if (voxels)
		std::printf(
		    "voxel_total voxel %.3f m (camera-frame cubes, majority "
		    "of their pixels): %s\n",
		    o.voxelSize, t.totalVoxels.scoresLine().c_str());
	else
		std::fprintf(stderr,
		             "bims-eval masks: voxel-level figures need --depth-valid "
		             "and --voxel-size > 0\n");
	if (o.json) writeMasksJson(o, *pairing, labels, bool(scans), voxels, t);
	printTotals(pairs.size(), t);
	return 0;
}

}  // namespace bims::apps
