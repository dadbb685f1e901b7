// bims-flow-labels' run (docs/flow.md): the flow labels of one RGB-D image
// pair, the observed flow of frame 1 towards frame 0 against the flow
// expected from frame 1's depth and a given relative pose T_C0C1, written
// as colour pictures with per-stage timings. The program's main only reads
// its command line into FlowLabelsOptions and calls runFlowLabels.
#pragma once

#include <bims/flow/consistency.h>
#include <bims/flow/params.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>

#include <opencv2/core.hpp>
#include <optional>
#include <string>

namespace bims::flow
{
/** What bims-flow-labels' command line gives (nullopt: not given). */
struct FlowLabelsOptions
{
	std::string rgb0;                   ///< previous RGB image
	std::string rgb1;                   ///< current RGB image
	std::string depth1;                 ///< current depth (16-bit PNG)
	std::string out;                    ///< output folder
	std::optional<std::string> config;  ///< experiment .ini ([flow])
	double depth_scale = 5000.0;        ///< depth units per metre
	double fx = 0, fy = 0;    ///< focal lengths [px] (<= 0: the default)
	double cx = -1, cy = -1;  ///< principal point [px] (< 0: the centre)
	std::string pose = "0 0 0 0 0 0";  ///< T_C0C1 'x y z yaw pitch roll'
};

/** The camera of a pair of \a cols x \a rows images: the given \a fx,
 * \a fy (each 525 px at 640 wide, scaled to the width, when <= 0) and
 * \a cx, \a cy (the image centre when < 0). */
mrpt::img::TCamera pairCamera(int cols, int rows, double fx, double fy,
                              double cx, double cy);

/** The pose 'x y z yaw pitch roll' (metres, degrees) of --pose; throws
 * UsageError unless it starts with 6 numbers. */
mrpt::poses::CPose3D parsePoseXyzYpr(const std::string& text);

/** The labels of one pair and how long each stage took. */
struct PairLabels
{
	cv::Mat observed;  ///< observed backward flow (CV_32FC2)
	cv::Mat expected;  ///< expected backward flow (CV_32FC2)
	cv::Mat labels;    ///< CV_8SC1 Label values
	LabelStats stats;
	double msObserved = 0, msExpected = 0, msLabels = 0;
};

/** Labels frame 1 of the pair (\a rgb0, \a rgb1: BGR; \a depth16: frame
 * 1's 16-bit depth, \a depthScale units per metre) seen by \a cam, frame 1
 * at \a T_CprevC in frame 0, with \a params. */
PairLabels labelPair(const cv::Mat& rgb0, const cv::Mat& rgb1,
                     const cv::Mat& depth16, double depthScale,
                     const mrpt::img::TCamera& cam,
                     const mrpt::poses::CPose3D& T_CprevC,
                     const FlowParams& params);

/** \a rgb (BGR) with its Diff pixels of \a labels darkened towards red. */
cv::Mat diffOverlay(const cv::Mat& rgb, const cv::Mat& labels);

/** bims-flow-labels: checks the options (no output may be an input), reads
 * the config and the images, labels the pair, writes observed_flow.png,
 * expected_flow.png, labels.png and overlay.png into the output folder and
 * prints the counts and timings on stdout. Returns the program's exit code
 * (0); errors are thrown. */
int runFlowLabels(const FlowLabelsOptions& o);

}  // namespace bims::flow
