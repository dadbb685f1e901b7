#include <bims/apps/app.h>
#include <bims/apps/bag_import_run.h>
#include <bims/apps/import_options.h>
#include <bims/apps/output_checks.h>
#include <bims/apps/progress_bar.h>
#include <bims/common/config.h>
#include <bims/io/output_paths.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/core/format.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace bims::apps
{
using bag::BagImportOptions;
using bag::BagImportParams;
using bag::BagImportSummary;
using bag::BagLayout;
using bag::bagTopics;
using bag::describeTopics;
using bag::importBag;

namespace
{
std::string channels(const BagImportSummary& s)
{
	std::string c;
	if (s.imuHasGyro) c += "gyro";
	if (s.imuHasAccel) c += std::string(c.empty() ? "" : ", ") + "accel";
	if (s.imuHasMag) c += std::string(c.empty() ? "" : ", ") + "mag";
	return c.empty() ? "nothing" : c;
}
}  // namespace

namespace
{
/** The report's lines on the depth's units, the extrinsics and the
 * intrinsics. */
std::string bagCameraLines(const BagImportSummary& sum)
{
	std::string r;
	if (sum.depthUnits > 0)
		r += mrpt::format("depth units %g m from %s\n", sum.depthUnits,
		                  sum.depthUnitsFrom.c_str());
	if (sum.depthToColour)
	{
		const auto& T = *sum.depthToColour;
		r += mrpt::format(
		    "depth registered to the colour camera with the recording's "
		    "extrinsics: t = (%.4f %.4f %.4f) m, rotation %.3f deg\n",
		    T.t[0], T.t[1], T.t[2], bag::rotationDeg(T));
	}
	if (sum.cameraToImu)
	{
		const auto& R = sum.cameraToImu->R;
		r += mrpt::format(
		    "IMU extrinsics from %s: R_IC = %.4f %.4f %.4f  %.4f %.4f %.4f  "
		    "%.4f %.4f %.4f\n",
		    sum.cameraToImuFrom.c_str(), R[0], R[1], R[2], R[3], R[4], R[5],
		    R[6], R[7], R[8]);
	}
	if (!sum.calibrationFile.empty())
		r += "camera and IMU calibration in " + sum.calibrationFile +
		     " (bims-odom --calib; copy its [calibration] into the "
		     "experiment's .ini for bims-run)\n";
	r += mrpt::format("intrinsics from %s: fx %.4f fy %.4f cx %.4f cy %.4f\n",
	                  sum.cameraFrom.c_str(), sum.camera.fx(), sum.camera.fy(),
	                  sum.camera.cx(), sum.camera.cy());
	if (sum.distortionIgnored)
		r += "the CameraInfo's " + sum.distortionModel +
		     " distortion is not modelled: the images are used as they are "
		     "(a pinhole camera)\n";
	return r;
}

/** The report's lines on the IMU. */
std::string bagImuLines(const BagImportSummary& sum,
                        const BagImportParams& params)
{
	std::string r;
	if (sum.imuSource.empty())
		r += "no IMU topic\n";
	else
	{
		r += mrpt::format("%zu IMU samples (%s) from %s", sum.imu,
		                  channels(sum).c_str(), sum.imuSource.c_str());
		if (sum.accelOnly == sum.imu && sum.imu > 0)
			r += ", labelled " + params.accelLabel + " (no gyro)";
		else if (sum.accelOnly > 0)
			r += mrpt::format(", labelled %s (%zu without gyro: %s)",
			                  params.imuLabel.c_str(), sum.accelOnly,
			                  params.accelLabel.c_str());
		else
			r += ", labelled " + params.imuLabel;
		r += "\n";
		if (sum.imuOutside > 0)
			r += mrpt::format(
			    "%zu IMU samples outside the frames' time span: left out\n",
			    sum.imuOutside);
		if (sum.imuLeftOut > 0)
			r += mrpt::format(
			    "%zu gyro samples outside the accelerometer's time span: "
			    "left out\n",
			    sum.imuLeftOut);
		if (sum.imuStampsBack > 0)
			r += mrpt::format(
			    "%zu IMU samples had a stamp not after the one before: left "
			    "out\n",
			    sum.imuStampsBack);
	}
	return r;
}
}  // namespace

std::string bagImportReport(const std::string& out, const BagImportSummary& sum,
                            const BagImportParams& params)
{
	std::string r = mrpt::format(
	    "%s: %zu RGB-D frames of %dx%d (depth %s from %s, %s)\n", out.c_str(),
	    sum.frames, sum.width, sum.height, sum.depthEncoding.c_str(),
	    sum.topics.depth.c_str(),
	    sum.topics.colour.empty()
	        ? "no colour"
	        : ("colour " + sum.colourEncoding + " from " + sum.topics.colour)
	              .c_str());
	for (const auto& n : sum.notes) r += n + "\n";
	if (sum.layout != BagLayout::Auto)
		r += "layout: " + std::string(choices(sum.layout).name(sum.layout)) +
		     "\n";
	r += bagCameraLines(sum);
	if (sum.unpaired > 0)
		r += mrpt::format(
		    "%zu of %zu depth images had no colour image within %g s "
		    "([import_bag] max_time_gap_s): left out\n",
		    sum.unpaired, sum.depthMessages, params.maxTimeGap);
	if (sum.stampsBack > 0)
		r += mrpt::format(
		    "%zu images had a stamp not after the one before on their "
		    "topic: left out\n",
		    sum.stampsBack);
	r += bagImuLines(sum, params);
	return r;
}

namespace
{
/** What every use of the options needs, --topics too. */
void checkBagsAndGz(const BagImportRunOptions& o)
{
	if (o.bags.empty()) throw UsageError("no bag given");
	checkGzLevel(o.gz);
}
}  // namespace

BagImport importBagChecked(const BagImportRunOptions& o,
                           const ProgressCallback& progress)
{
	checkBagsAndGz(o);
	std::vector<std::string> inputs = o.bags;
	inputs.push_back(o.config.value_or(""));
	if (o.out.empty()) throw UsageError("-o OUT.rawlog is required");
	checkOutputsSpareInputs(inputs, {o.out, groundTruthDirFor(o.out)});

	BagImportParams params;
	if (const auto cfg = openImportConfig(o.config))
		params.loadFromConfigFile(*cfg);
	if (o.layout)
	{
		const auto c = choices(BagLayout::Auto);
		const auto l = c.find(*o.layout);
		if (!l)
			throw UsageError("--layout " + *o.layout +
			                 ": one of auto, realsense, tum, rs-sdk");
		params.layout = *l;
	}
	if (o.depthUnits)
	{
		if (!(*o.depthUnits >= 1e-6 && *o.depthUnits <= 0.1))
			throw UsageError(mrpt::format(
			    "--depth-units %g: metres per unit, in [1e-6, 0.1]",
			    *o.depthUnits));
		params.depthUnits = *o.depthUnits;
	}
	BagImportOptions opt;
	opt.maxFrames = o.max_frames;
	opt.gzLevel = o.gz;
	opt.progress = progress;
	return {importBag(o.bags, o.out, params, opt), params};
}

int runBagImport(const BagImportRunOptions& o)
{
	if (o.listTopics)
	{
		checkBagsAndGz(o);
		std::vector<std::string> damage;
		std::fputs(describeTopics(bagTopics(o.bags, &damage)).c_str(), stdout);
		for (const auto& d : damage)
			std::fprintf(stderr, "bims-import-bag: warning: %s\n", d.c_str());
		return 0;
	}
	ProgressBar bar("import", 0, o.progress);
	const BagImport r = importBagChecked(o, bar.callback());
	std::fputs(bagImportReport(o.out, r.summary, r.params).c_str(), stdout);
	return 0;
}

}  // namespace bims::apps
