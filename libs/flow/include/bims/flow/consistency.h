// Diff / notDiff labels: observed vs egomotion-predicted flow (paper III-B).
#pragma once

#include <bims/flow/params.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>
#include <opencv2/core.hpp>

namespace bims::flow
{
/** Per-pixel label values (CV_8SC1). */
enum Label : int8_t
{
	kNoLabel = -1,  ///< no depth, too far, or the flow leaves the image
	kNotDiff = 0,   ///< observed flow consistent with the egomotion
	kDiff = 1       ///< inconsistent: independent motion
};

/** Counts of one labelling. */
struct LabelStats
{
	size_t diff = 0, notDiff = 0, none = 0;
};

/** Labels the current frame's pixels. \a observed and \a expected are
 * backward flows (CV_32FC2, NaN = none), \a depth CV_32FC1 metres of the
 * current frame. A pixel gets a label only with a finite depth in
 * (0, max_depth_m], a finite expected flow, and both flows landing inside
 * the image. Threshold: diff_threshold_px, plus depth_noise_sigmas times the
 * expected-flow standard deviation caused by depth noise
 * (f * |t_xy| * sigma_z / z^2, sigma_z = a z^2) when enabled; \a T_CprevC
 * gives t. Pixels on depth edges get no label when depth_edge_rel > 0.
 * With visible_change_grey > 0, \a tensor (structureTensor() of the current
 * image, CV_32FC3) is required: a pixel whose flow difference d changes the
 * image by less than visible_change_grey RMS is notDiff. Returns CV_8SC1 of
 * Label values; throws std::invalid_argument on mismatched inputs. */
cv::Mat labelConsistency(const cv::Mat& observed, const cv::Mat& expected,
                         const cv::Mat& depth, const mrpt::img::TCamera& cam,
                         const mrpt::poses::CPose3D& T_CprevC,
                         const FlowParams& p, LabelStats* stats = nullptr,
                         const cv::Mat* tensor = nullptr);

/** Colour picture of a flow field (hue = direction, value = magnitude,
 * saturating at \a maxMagPx; black where NaN). CV_8UC3 BGR. */
cv::Mat flowToColor(const cv::Mat& flow, double maxMagPx);

/** Colour picture of labels: Diff red, notDiff grey, none black. */
cv::Mat labelsToColor(const cv::Mat& labels);

}  // namespace bims::flow
