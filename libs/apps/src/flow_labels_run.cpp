#include <bims/apps/app.h>
#include <bims/apps/flow_labels_run.h>
#include <bims/apps/output_checks.h>
#include <bims/common/choice.h>
#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/flow/observed_flow.h>
#include <bims/io/image_file.h>
#include <bims/io/output_paths.h>
#include <mrpt/core/bits_math.h>
#include <mrpt/system/filesystem.h>

#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>

namespace bims::apps
{
using flow::diffOverlay;
using flow::FlowParams;
using flow::flowToColor;
using flow::labelPair;
using flow::labelsToColor;
using flow::pairCamera;
using flow::PairLabels;

namespace
{
cv::Mat readImage(const std::string& path, int flags, const ImageLimits& limits)
{
	return readImageFile(path, flags, "image", limits);
}
}  // namespace

mrpt::poses::CPose3D parsePoseXyzYpr(const std::string& text)
{
	double pv[6];
	std::istringstream ps(text);
	for (double& x : pv)
		if (!(ps >> x))
			throw UsageError("--pose needs 6 numbers 'x y z yaw pitch roll'");
	return mrpt::poses::CPose3D(pv[0], pv[1], pv[2], mrpt::DEG2RAD(pv[3]),
	                            mrpt::DEG2RAD(pv[4]), mrpt::DEG2RAD(pv[5]));
}

int runFlowLabels(const FlowLabelsOptions& o)
{
	checkOutputsSpareInputs({o.rgb0, o.rgb1, o.depth1, o.config.value_or("")},
	                        {o.out});
	FlowParams params;
	ImageLimits limits;  // [input] of the config, else the defaults
	if (o.config)
	{
		if (!mrpt::system::fileExists(*o.config))
			throw std::runtime_error(*o.config + ": no such config file");
		const auto cfg = openIniFile(*o.config);
		checkExperimentSections(*cfg);
		params.loadFromConfigFile(*cfg, "flow");
		limits.loadFromConfigFile(*cfg, "input");
	}
	const cv::Mat rgb0 = readImage(o.rgb0, cv::IMREAD_COLOR, limits);
	const cv::Mat rgb1 = readImage(o.rgb1, cv::IMREAD_COLOR, limits);
	const cv::Mat d16 = readImage(o.depth1, cv::IMREAD_UNCHANGED, limits);
	if (d16.type() != CV_16UC1)
		throw std::runtime_error(o.depth1 +
		                         ": depth must be a 16-bit single-channel PNG");
	if (rgb0.size() != rgb1.size() || rgb1.size() != d16.size())
		throw std::runtime_error("images differ in size: " + o.rgb0 + ", " +
		                         o.rgb1 + ", " + o.depth1);
	const auto cam = pairCamera(rgb1.cols, rgb1.rows, o.fx, o.fy, o.cx, o.cy);
	const auto T_CprevC = parsePoseXyzYpr(o.pose);
	const PairLabels r =
	    labelPair(rgb0, rgb1, d16, o.depth_scale, cam, T_CprevC, params);

	makeDirs(o.out);
	writeImageFile(o.out + "/observed_flow.png", flowToColor(r.observed, 10.0));
	writeImageFile(o.out + "/expected_flow.png", flowToColor(r.expected, 10.0));
	writeImageFile(o.out + "/labels.png", labelsToColor(r.labels));
	writeImageFile(o.out + "/overlay.png", diffOverlay(rgb1, r.labels));
	const auto& st = r.stats;
	const size_t labelled = st.diff + st.notDiff;
	std::printf(
	    "pixels %dx%d  labelled %zu  Diff %zu (%.2f %%)  notDiff %zu  none "
	    "%zu\n",
	    r.labels.cols, r.labels.rows, labelled, st.diff,
	    labelled ? 100.0 * st.diff / labelled : 0.0, st.notDiff, st.none);
	std::printf(
	    "ms: observed flow (%s) %.1f  expected flow %.1f  labels %.1f\n",
	    choiceName(params.method), r.msObserved, r.msExpected, r.msLabels);
	std::printf("pictures in %s/\n", o.out.c_str());
	return 0;
}

}  // namespace bims::apps
