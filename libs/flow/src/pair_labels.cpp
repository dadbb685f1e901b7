#include <bims/common/app.h>
#include <bims/common/clock.h>
#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/common/image_file.h>
#include <bims/common/output_paths.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/observed_flow.h>
#include <bims/flow/pair_labels.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/core/bits_math.h>
#include <mrpt/system/filesystem.h>

#include <chrono>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

namespace bims::flow
{
namespace
{
cv::Mat readImage(const std::string& path, int flags)
{
	return readImageFile(path, flags, "image");
}
}  // namespace

mrpt::img::TCamera pairCamera(int cols, int rows, double fx, double fy,
                              double cx, double cy)
{
	mrpt::img::TCamera cam;
	cam.ncols = cols;
	cam.nrows = rows;
	const double f = 525.0 * cols / 640.0;
	cam.setIntrinsicParamsFromValues(fx > 0 ? fx : f, fy > 0 ? fy : f,
	                                 cx >= 0 ? cx : cols / 2.0,
	                                 cy >= 0 ? cy : rows / 2.0);
	return cam;
}

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

PairLabels labelPair(const cv::Mat& rgb0, const cv::Mat& rgb1,
                     const cv::Mat& depth16, double depthScale,
                     const mrpt::img::TCamera& cam,
                     const mrpt::poses::CPose3D& T_CprevC,
                     const FlowParams& params)
{
	cv::Mat g0, g1, depth;
	cv::cvtColor(rgb0, g0, cv::COLOR_BGR2GRAY);
	cv::cvtColor(rgb1, g1, cv::COLOR_BGR2GRAY);
	depth16.convertTo(depth, CV_32FC1, 1.0 / depthScale);

	PairLabels r;
	ObservedFlow of(params);
	auto t0 = std::chrono::steady_clock::now();
	r.observed = of.compute(g0, g1);
	r.msObserved = msSince(t0);
	t0 = std::chrono::steady_clock::now();
	r.expected = expectedFlow(params.expected, depth, cam, T_CprevC);
	r.msExpected = msSince(t0);
	t0 = std::chrono::steady_clock::now();
	// the current image's structure tensor, computed with the flow when
	// [flow] asks for it (visible_change_grey > 0: the default)
	const cv::Mat& tensor = of.tensor();
	r.labels =
	    labelConsistency(r.observed, r.expected, depth, cam, T_CprevC, params,
	                     &r.stats, tensor.empty() ? nullptr : &tensor);
	r.msLabels = msSince(t0);
	return r;
}

cv::Mat diffOverlay(const cv::Mat& rgb, const cv::Mat& labels)
{
	cv::Mat overlay = rgb.clone();
	for (int v = 0; v < labels.rows; v++)
		for (int u = 0; u < labels.cols; u++)
			if (labels.at<int8_t>(v, u) == kDiff)
				overlay.at<cv::Vec3b>(v, u) =
				    overlay.at<cv::Vec3b>(v, u) / 2 + cv::Vec3b(0, 0, 127);
	return overlay;
}

int runFlowLabels(const FlowLabelsOptions& o)
{
	checkOutputsSpareInputs({o.rgb0, o.rgb1, o.depth1, o.config.value_or("")},
	                        {o.out});
	FlowParams params;
	if (o.config)
	{
		if (!mrpt::system::fileExists(*o.config))
			throw std::runtime_error(*o.config + ": no such config file");
		const auto cfg = openIniFile(*o.config);
		checkExperimentSections(*cfg);
		params.loadFromConfigFile(*cfg, "flow");
	}
	const cv::Mat rgb0 = readImage(o.rgb0, cv::IMREAD_COLOR);
	const cv::Mat rgb1 = readImage(o.rgb1, cv::IMREAD_COLOR);
	const cv::Mat d16 = readImage(o.depth1, cv::IMREAD_UNCHANGED);
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

}  // namespace bims::flow
