#include <bims/apps/app.h>
#include <bims/apps/import_options.h>
#include <bims/apps/output_checks.h>
#include <bims/apps/progress_bar.h>
#include <bims/apps/stray_import_run.h>
#include <bims/common/config.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/core/format.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

namespace bims::apps
{
using eval::importStray;
using eval::readStrayCapture;
using eval::StrayCapture;
using eval::StrayImportOptions;
using eval::StrayImportParams;
using eval::StrayImportSummary;
using eval::strayInputFiles;
using eval::strayReferencePathFor;

std::string strayImportReport(const std::string& out,
                              const StrayImportSummary& sum)
{
	std::string r = mrpt::format(
	    "%s: %zu RGB-D frames of %dx%d (%s), %zu IMU observations (%zu before "
	    "the first frame)\n",
	    out.c_str(), sum.frames, sum.width, sum.height,
	    sum.colour ? mrpt::format("colour from rgb.mp4, %dx%d resized",
	                              sum.videoWidth, sum.videoHeight)
	                     .c_str()
	               : "no colour: no rgb.mp4",
	    sum.imu, sum.imuBeforeFirst);
	r += mrpt::format(
	    "intrinsics of the depth grid: fx %.4f fy %.4f cx %.4f "
	    "cy %.4f\n",
	    sum.camera.fx(), sum.camera.fy(), sum.camera.cx(), sum.camera.cy());
	if (sum.confidence)
		r += mrpt::format(
		    "confidence >= %d kept: %llu of %llu depth readings dropped "
		    "(%.1f %%)\n",
		    sum.minConfidence, static_cast<unsigned long long>(sum.dropped),
		    static_cast<unsigned long long>(sum.readings),
		    sum.readings ? 100.0 * double(sum.dropped) / double(sum.readings)
		                 : 0.0);
	else
		r += mrpt::format(
		    "no confidence/ folder: all %llu depth readings kept\n",
		    static_cast<unsigned long long>(sum.readings));
	r += mrpt::format(
	    "%s: %zu ARKit poses (a reference, not ground truth), the first %zu "
	    "frames left out (no position yet)\n",
	    sum.referencePath.c_str(), sum.referencePoses, sum.referenceLeftOut);
	if (sum.framesSameStamp + sum.imuSameStamp + sum.imuAfterLast > 0)
		r += mrpt::format(
		    "left out: %zu frames and %zu IMU samples on the 100 ns tick of "
		    "the one before, %zu IMU samples after the last frame\n",
		    sum.framesSameStamp, sum.imuSameStamp, sum.imuAfterLast);
	for (const auto& n : sum.notes) r += n + "\n";
	return r;
}

StrayImportSummary importStrayChecked(const StrayImportRunOptions& o,
                                      const ProgressCallback& progress)
{
	checkOutputsSpareInputs({o.folder, o.config.value_or("")},
	                        {o.out, strayReferencePathFor(o.out)});
	checkGzLevel(o.gz);
	StrayImportParams params;
	if (const auto cfg = openImportConfig(o.config))
		params.loadFromConfigFile(*cfg);
	else
		std::fprintf(stderr,
		             "bims-import-stray: no --config: [import_stray] "
		             "min_confidence %d, colour %dx%d without rgb.mp4, labels "
		             "%s and %s\n",
		             params.min_confidence, params.colour_width,
		             params.colour_height, params.rgbd_label.c_str(),
		             params.imu_label.c_str());
	StrayImportOptions opt;
	opt.maxFrames = o.max_frames;
	opt.gzLevel = o.gz;
	opt.progress = progress;
	// the capture's files are inputs too: -o FOLDER/imu.csv is refused
	const StrayCapture cap = readStrayCapture(o.folder);
	auto inputs = strayInputFiles(cap);
	inputs.push_back(o.config.value_or(""));
	checkOutputsSpareInputs(inputs, {o.out, strayReferencePathFor(o.out)});
	return importStray(cap, o.out, params, opt);
}

int runStrayImport(const StrayImportRunOptions& o)
{
	ProgressBar bar("bims-import-stray", 0, o.progress);
	const auto sum = importStrayChecked(o, bar.callback());
	for (const auto& w : sum.warnings)
		std::fprintf(stderr, "bims-import-stray: warning: %s\n", w.c_str());
	std::fputs(strayImportReport(o.out, sum).c_str(), stdout);
	return 0;
}

}  // namespace bims::apps
