#include <bims/apps/app.h>
#include <bims/apps/import_options.h>
#include <bims/apps/output_checks.h>
#include <bims/apps/progress_bar.h>
#include <bims/apps/tum_import_run.h>
#include <bims/common/config.h>
#include <bims/eval/pose_utils.h>
#include <bims/io/output_paths.h>
#include <bims/sim/imu.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/core/format.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

namespace bims::apps
{
using eval::bonnMarkerToCamera;
using eval::ImportOptions;
using eval::ImportParams;
using eval::ImportSummary;
using eval::importTum;
using eval::readTumFolder;
using eval::TumFolder;
using eval::tumInputFiles;

std::string importReport(const std::string& out, const ImportSummary& sum,
                         bool synthetic, bool bonnConverted,
                         const ImportParams& params)
{
	std::string r = mrpt::format("%s: %zu RGB-D frames, %zu IMU observations",
	                             out.c_str(), sum.frames, sum.imu);
	if (sum.imu)
		r += std::string(synthetic ? " (synthetic, " : " (") + "label '" +
		     sum.imuLabel + "')";
	if (sum.accel)
		r += mrpt::format(
		    ", %zu accelerometer samples of accelerometer.txt (label '%s', "
		    "accelerometer only)",
		    sum.accel, params.accelLabel.c_str());
	r += "\n";
	if (sum.gtPoses || sum.framesWithoutGt)
		r += mrpt::format(
		    "%s/groundtruth.txt: %zu poses (T_WC at the frames' stamps%s), "
		    "%zu frames outside the ground truth\n",
		    sum.gtDir.c_str(), sum.gtPoses,
		    bonnConverted ? ", Bonn-converted" : "", sum.framesWithoutGt);
	else
		r += mrpt::format("%s: no groundtruth.txt in the folder\n",
		                  sum.gtDir.c_str());
	return r;
}

TumImport importTumChecked(const ImportRunOptions& o,
                           const ProgressCallback& progress)
{
	checkOutputsSpareInputs({o.folder, o.config.value_or("")},
	                        {o.out, groundTruthDirFor(o.out)});
	checkGzLevel(o.gz);
	ImportParams params;
	const auto cfg = openImportConfig(o.config);
	if (cfg)
	{
		std::vector<std::string> sections;
		cfg->getAllSections(sections);
		if (sections.empty())
			throw ConfigError(*o.config +
			                  ": no settings at all (an empty file?); without "
			                  "--config bims-import-tum uses the TUM default "
			                  "camera");
		params.loadFromConfigFile(*cfg);
	}
	// read once; its files are inputs too: -o FOLDER/rgb.txt is refused
	TumFolder tum = readTumFolder(o.folder, params);
	auto inputs = tumInputFiles(tum);
	inputs.push_back(o.config.value_or(""));
	checkOutputsSpareInputs(inputs, {o.out, groundTruthDirFor(o.out)});
	if (!cfg || !cfg->sectionExists("camera"))
		std::fprintf(
		    stderr,
		    "bims-import-tum: %s: using the TUM default camera "
		    "(fx=fy=525, cx=319.5, cy=239.5, 640x480, depth scale "
		    "5000)\n",
		    cfg ? ("no [camera] in " + *o.config).c_str() : "no --config");

	ImportOptions opt;
	opt.maxFrames = o.max_frames;
	opt.bonnGt = o.bonn_gt;
	opt.gzLevel = o.gz;
	opt.progress = progress;
	const bool bonnConverted = opt.bonnGt || params.bonnGt;
	if (o.synth_imu)
	{
		// the folder read above (its ground truth)
		if (!tum.hasGroundTruth)
			throw std::runtime_error(
			    o.folder +
			    ": --synth-imu needs groundtruth.txt to synthesise from");
		Trajectory gt = tum.groundTruth;
		if (bonnConverted)
			for (auto& p : gt) p.T_WC = bonnMarkerToCamera(p.T_WC);
		const ImuSynthesis synthesize =
		    o.synthesize ? o.synthesize
		                 : ImuSynthesis(sim::synthesizeImportImu);
		opt.extra = synthesize(gt, params.imuLabel, cfg.get(), o.seed);
	}

	TumImport r;
	r.summary = importTum(std::move(tum), o.out, params, opt);
	r.params = params;
	r.bonnConverted = bonnConverted;
	return r;
}

namespace
{
/** A folder of the Bonn RGB-D Dynamic dataset, by its name (rgbd_bonn_*,
 * or any name with "bonn"): its ground truth is of the motion-capture
 * marker, not of the camera. */
bool looksLikeBonnFolder(const std::string& folder)
{
	std::filesystem::path a =
	    std::filesystem::absolute(folder).lexically_normal();
	if (a.filename().empty()) a = a.parent_path();  // "FOLDER/"
	std::string p = a.filename().string();
	std::transform(p.begin(), p.end(), p.begin(),
	               [](unsigned char c) { return std::tolower(c); });
	return p.find("bonn") != std::string::npos;
}
}  // namespace

int runImport(const ImportRunOptions& o)
{
	ProgressBar bar("import", 0, o.progress);
	const TumImport r = importTumChecked(o, bar.callback());
	std::fputs(
	    importReport(o.out, r.summary, o.synth_imu, r.bonnConverted, r.params)
	        .c_str(),
	    stdout);
	if (r.summary.gtPoses > 0 && !r.bonnConverted &&
	    looksLikeBonnFolder(o.folder))
		std::fprintf(
		    stderr,
		    "bims-import-tum: note: %s looks like a Bonn RGB-D Dynamic folder "
		    "(its name): its groundtruth.txt holds the motion-capture marker's "
		    "poses, kept as they are in %s/groundtruth.txt. For the camera's "
		    "poses (what bims-eval traj compares an estimate with), import "
		    "with -c bonn.ini or --bonn-gt\n",
		    o.folder.c_str(), r.summary.gtDir.c_str());
	return 0;
}

}  // namespace bims::apps
