// The flow labels of one RGB-D image pair (docs/flow.md): the observed flow
// of frame 1 towards frame 0 against the flow expected from frame 1's depth
// and a given relative pose T_C0C1, with per-stage timings. bims-flow-labels'
// run: bims/apps/flow_labels_run.h.
#pragma once

#include <bims/flow/consistency.h>
#include <bims/flow/params.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>

#include <opencv2/core.hpp>
#include <string>

namespace bims::flow
{
/** The camera of a pair of \a cols x \a rows images: the given \a fx,
 * \a fy (each 525 px at 640 wide, scaled to the width, when <= 0) and
 * \a cx, \a cy (the image centre when < 0). */
mrpt::img::TCamera pairCamera(int cols, int rows, double fx, double fy,
                              double cx, double cy);

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

}  // namespace bims::flow
