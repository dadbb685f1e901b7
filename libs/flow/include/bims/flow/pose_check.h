// Where do the flow labels' false positives come from? The observed flow of
// one frame labelled against the expected flow of several relative poses
// T_{C(t-1) C(t)} (bims-flow-check, docs/flow.md):
//   ego   the egomotion stage's pose
//   used  the pose the pipeline used (ego, or its dense-flow refinement)
//   gt    the ground truth's
//   flow  the SE(3) fitted to the dense observed flow from ego
// Per pose the Diff fraction of the valid-depth pixels and the median
// |observed - expected| flow, and the poses' differences.
#pragma once

#include <bims/flow/params.h>

#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>
#include <opencv2/core.hpp>

#include <array>

namespace bims::flow
{
/** How well one relative pose explains the observed flow. */
struct PoseScore
{
	double diffFraction = 0;  ///< Diff / valid-depth pixels
	double medianPx = 0;      ///< median |obs - exp| over labelled pixels
};

/** Labels \a observed against the expected flow of \a T (\a p.expected
 * model over \a depth) with labelConsistency(); \a validPx: the pixels with
 * depth; \a tensor: structureTensor() of the current image. \a labelsOut:
 * the labels (1 Diff, 0 notDiff, -1 none), when given. */
PoseScore scorePose(const cv::Mat& observed, const cv::Mat& depth,
                    const mrpt::img::TCamera& cam,
                    const mrpt::poses::CPose3D& T, const FlowParams& p,
                    double validPx, const cv::Mat& tensor,
                    cv::Mat* labelsOut = nullptr);

/** The angle of a^-1 b [deg]. */
double rotationDeg(const mrpt::poses::CPose3D& a,
                   const mrpt::poses::CPose3D& b);
/** The distance between the positions of a and b [mm]. */
double translationMm(const mrpt::poses::CPose3D& a,
                     const mrpt::poses::CPose3D& b);

/** One frame's comparison of the four pose sources. */
struct PoseSourceCheck
{
	static constexpr size_t kValues = 19;
	/** The names of values, in order (the summary's and CSV's columns):
	 * diff_%_{ego,used,gt,flow}, median_px_{...}, rot_{ego_gt, ego_flow,
	 * gt_flow, used_flow}_deg, t_{...}_mm, gt_rot_deg, gt_t_mm,
	 * edge_share_used (the share of the used pose's Diff pixels on depth
	 * edges). */
	static const std::array<const char*, kValues>& names();
	double validPx = 0;  ///< pixels with depth
	std::array<double, kValues> values{};
	cv::Mat labelsUsed;  ///< the used pose's labels (scorePose)
};

/** Scores the poses \a ego, \a used and \a gt (T_{C(t-1) C(t)}) and the
 * SE(3) fitted to \a observed from \a ego against \a observed, the flow
 * from the previous image to the current one (\a grey, \a depth, \a cam);
 * \a p: the flow parameters of the run. */
PoseSourceCheck checkPoseSources(const cv::Mat& observed, const cv::Mat& depth,
                                 const cv::Mat& grey,
                                 const mrpt::img::TCamera& cam,
                                 const mrpt::poses::CPose3D& ego,
                                 const mrpt::poses::CPose3D& used,
                                 const mrpt::poses::CPose3D& gt,
                                 const FlowParams& p);

}  // namespace bims::flow
