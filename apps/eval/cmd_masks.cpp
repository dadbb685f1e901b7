#include <bims/common/app.h>
#include <bims/common/rawlog.h>
#include <bims/eval/depth_consistency.h>
#include <bims/eval/json.h>
#include <bims/eval/mask_metrics.h>
#include <bims/eval/plots.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

#include "commands.h"

namespace ev = bims::eval;
namespace fs = std::filesystem;

namespace
{
struct MaskFile
{
	long index;
	std::string name;  // NNNNNN.png
};

/** Files named <digits>.png in \a dir, sorted by their number. */
std::vector<MaskFile> listMasks(const std::string& dir)
{
	if (!fs::is_directory(dir))
		throw std::runtime_error(dir + ": mask directory not found");
	std::vector<MaskFile> out;
	for (const auto& e : fs::directory_iterator(dir))
	{
		const auto p = e.path();
		const std::string stem = p.stem().string();
		if (p.extension() != ".png" || stem.empty() ||
		    !std::all_of(stem.begin(), stem.end(),
		                 [](unsigned char c) { return std::isdigit(c); }))
			continue;
		out.push_back({std::stol(stem), p.filename().string()});
	}
	std::sort(out.begin(), out.end(),
	          [](const MaskFile& a, const MaskFile& b)
	          { return a.index < b.index; });
	return out;
}

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

std::string frameName(long k)
{
	char b[32];
	std::snprintf(b, sizeof(b), "%06ld", k);
	return b;
}
}  // namespace

int cmdMasks(int argc, char** argv)
{
	TCLAP::CmdLine cmd(
	    "Precision, recall, F1 and IoU of predicted moving-pixel masks "
	    "(8-bit PNG, 255 = moving, NNNNNN.png = 3D scan index) against ground "
	    "truth, per frame and in total, over pixels with valid depth. The last "
	    "line is 'total precision P recall R F1 F IoU I'.",
	    ' ', "0.1");
	TCLAP::UnlabeledValueArg<std::string> gtArg(
	    "GT_MASK_DIR", "ground-truth masks", true, "", "GT_MASK_DIR", cmd);
	TCLAP::UnlabeledValueArg<std::string> predArg(
	    "PRED_MASK_DIR", "predicted masks", true, "", "PRED_MASK_DIR", cmd);
	TCLAP::ValueArg<std::string> depth(
	    "", "depth-valid",
	    "rawlog whose 3D scans give the valid-depth pixels (and the overlay "
	    "background); without it every pixel counts",
	    false, "", "IN.rawlog", cmd);
	TCLAP::ValueArg<std::string> plotDir(
	    "o", "plot-dir",
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
	TCLAP::SwitchArg quiet("q", "quiet", "no per-frame lines", cmd);
	bims::parseCommandLine(cmd, argc, argv);

	const std::string gtDir = gtArg.getValue(), predDir = predArg.getValue();
	const auto gtFiles = listMasks(gtDir);
	if (!fs::is_directory(predDir))
		throw std::runtime_error(predDir + ": mask directory not found");
	if (gtFiles.empty())
		throw std::runtime_error(gtDir + ": no NNNNNN.png masks");

	std::string outDir;
	if (!noPlots.getValue())
	{
		outDir = plotDir.getValue();
		if (outDir.empty())
		{
			std::string p = predDir;
			while (p.size() > 1 && p.back() == '/') p.pop_back();
			outDir = p + "_eval";
		}
		bims::makeDirs(outDir);
	}
	std::unique_ptr<ScanStream> scans;
	if (depth.isSet()) scans = std::make_unique<ScanStream>(depth.getValue());

	if (voxel.getValue() < 0 || !std::isfinite(voxel.getValue()))
		throw bims::UsageError("--voxel-size must be >= 0");
	ev::MaskMetrics total, totalVoxels;
	size_t compared = 0, missing = 0;
	std::string jsonFrames;
	for (const auto& f : gtFiles)
	{
		const std::string predPath = predDir + "/" + f.name;
		if (!fs::exists(predPath))
		{
			missing++;
			continue;
		}
		const std::string gtPath = gtDir + "/" + f.name;
		const cv::Mat g = ev::loadMask(gtPath), p = ev::loadMask(predPath);
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
		try
		{
			m.accumulate(g, p, valid);
			if (!depthM.empty() && voxel.getValue() > 0)
				totalVoxels +=
				    ev::voxelMaskMetrics(g, p, depthM, cam.fx(), cam.fy(),
				                         cam.cx(), cam.cy(), voxel.getValue());
		}
		catch (const std::invalid_argument& e)
		{
			throw std::runtime_error(gtPath + " vs " + predPath + ": " +
			                         e.what());
		}
		total += m;
		compared++;
		const std::string line = "frame " + frameName(f.index) + " tp " +
		                         std::to_string(m.tp) + " fp " +
		                         std::to_string(m.fp) + " fn " +
		                         std::to_string(m.fn) + " " + m.scoresLine();
		if (!quiet.getValue()) std::printf("%s\n", line.c_str());
		if (!outDir.empty())
			ev::writePng(outDir + "/" + f.name,
			             ev::maskOverlay(g, p, valid, background,
			                             "frame " + frameName(f.index) + "  " +
			                                 m.scoresLine()));
		if (!jsonFrames.empty()) jsonFrames += ",\n";
		jsonFrames += "    {\"frame\": " + std::to_string(f.index) +
		              ", \"metrics\": " + m.toJson() + "}";
	}
	if (compared == 0)
		throw std::runtime_error(
		    predDir + ": none of the " + std::to_string(gtFiles.size()) +
		    " ground-truth mask names of " + gtDir + " is present");
	if (missing)
		std::fprintf(
		    stderr,
		    "bims-eval masks: warning: %zu of %zu ground-truth frames have no "
		    "prediction in %s (not counted)\n",
		    missing, gtFiles.size(), predDir.c_str());
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
		std::ofstream jf(json.getValue());
		jf << "{\n  \"gt\": " << ev::jsonString(gtDir)
		   << ",\n  \"pred\": " << ev::jsonString(predDir)
		   << ",\n  \"frames_compared\": " << compared
		   << ",\n  \"frames_missing\": " << missing
		   << ",\n  \"depth_valid_only\": " << (scans ? "true" : "false")
		   << ",\n  \"total\": " << total.toJson();
		if (voxels)
			jf << ",\n  \"voxel_size_m\": " << voxel.getValue()
			   << ",\n  \"total_voxels\": " << totalVoxels.toJson();
		jf << ",\n  \"frames\": [\n" << jsonFrames << "\n  ]\n}\n";
		if (!jf) throw std::runtime_error(json.getValue() + ": cannot write");
	}
	std::printf(
	    "total_counts frames %zu tp %llu fp %llu fn %llu tn %llu invalid "
	    "%llu\n",
	    compared, static_cast<unsigned long long>(total.tp),
	    static_cast<unsigned long long>(total.fp),
	    static_cast<unsigned long long>(total.fn),
	    static_cast<unsigned long long>(total.tn),
	    static_cast<unsigned long long>(total.invalid));
	std::printf("total %s\n", total.scoresLine().c_str());
	return 0;
}
