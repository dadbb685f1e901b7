#include <bims/flow/consistency.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/flow_pose.h>
#include <bims/flow/observed_flow.h>
#include <bims/flow/pose_check.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace bims::flow
{
using mrpt::poses::CPose3D;

PoseScore scorePose(const cv::Mat& observed, const cv::Mat& depth,
                    const mrpt::img::TCamera& cam, const CPose3D& T,
                    const FlowParams& p, double validPx, const cv::Mat& tensor,
                    cv::Mat* labelsOut)
{
	const cv::Mat exp = expectedFlow(p.expected, depth, cam, T);
	LabelStats st;
	const cv::Mat lab =
	    labelConsistency(observed, exp, depth, cam, T, p, &st, &tensor);
	std::vector<float> d;
	d.reserve(st.diff + st.notDiff);
	for (int v = 0; v < lab.rows; v++)
		for (int u = 0; u < lab.cols; u++)
			if (lab.at<int8_t>(v, u) >= 0)
			{
				const cv::Vec2f e =
				    exp.at<cv::Vec2f>(v, u) - observed.at<cv::Vec2f>(v, u);
				d.push_back(std::hypot(e[0], e[1]));
			}
	PoseScore s;
	s.diffFraction = validPx > 0 ? st.diff / validPx : 0;
	if (!d.empty())
	{
		std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
		s.medianPx = d[d.size() / 2];
	}
	if (labelsOut) *labelsOut = lab;
	return s;
}

double rotationDeg(const CPose3D& a, const CPose3D& b)
{
	const auto R = (b - a).getRotationMatrix();  // a^-1 b
	const double c =
	    std::clamp((R(0, 0) + R(1, 1) + R(2, 2) - 1) / 2, -1.0, 1.0);
	return std::acos(c) * 180.0 / M_PI;
}

double translationMm(const CPose3D& a, const CPose3D& b)
{
	return 1000.0 * std::sqrt((a.x() - b.x()) * (a.x() - b.x()) +
	                          (a.y() - b.y()) * (a.y() - b.y()) +
	                          (a.z() - b.z()) * (a.z() - b.z()));
}

const std::array<const char*, PoseSourceCheck::kValues>&
PoseSourceCheck::names()
{
	static const std::array<const char*, kValues> n = {
	    "diff_%_ego",       "diff_%_used",     "diff_%_gt",
	    "diff_%_flow",      "median_px_ego",   "median_px_used",
	    "median_px_gt",     "median_px_flow",  "rot_ego_gt_deg",
	    "rot_ego_flow_deg", "rot_gt_flow_deg", "rot_used_flow_deg",
	    "t_ego_gt_mm",      "t_ego_flow_mm",   "t_gt_flow_mm",
	    "t_used_flow_mm",   "gt_rot_deg",      "gt_t_mm",
	    "edge_share_used"};
	return n;
}

PoseSourceCheck checkPoseSources(const cv::Mat& observed, const cv::Mat& depth,
                                 const cv::Mat& grey,
                                 const mrpt::img::TCamera& cam,
                                 const CPose3D& E, const CPose3D& U,
                                 const CPose3D& G, const FlowParams& p)
{
	PoseSourceCheck c;
	c.validPx = cv::countNonZero(depth > 0);
	FlowParams pSE3 = p;
	pSE3.refine_pose = RefinePose::SE3;
	const cv::Mat S = structureTensor(grey, p.texture_window_px);
	const auto ref = refinePoseWithFlow(observed, depth, cam, E,
	                                    flowPoseParamsFrom(pSE3), nullptr, &S);
	const CPose3D V = ref.T_CprevC;
	const double n = c.validPx;
	const auto sE = scorePose(observed, depth, cam, E, p, n, S);
	const auto sU = scorePose(observed, depth, cam, U, p, n, S, &c.labelsUsed);
	const auto sG = scorePose(observed, depth, cam, G, p, n, S);
	const auto sV = scorePose(observed, depth, cam, V, p, n, S);
	const cv::Mat edges = depthEdgeMask(depth, 0.05, 2);
	const double nDiff = cv::countNonZero(c.labelsUsed == 1);
	const double nDiffEdge =
	    cv::countNonZero((c.labelsUsed == 1) & (edges > 0));
	c.values = {sE.diffFraction * 100,
	            sU.diffFraction * 100,
	            sG.diffFraction * 100,
	            sV.diffFraction * 100,
	            sE.medianPx,
	            sU.medianPx,
	            sG.medianPx,
	            sV.medianPx,
	            rotationDeg(E, G),
	            rotationDeg(E, V),
	            rotationDeg(G, V),
	            rotationDeg(U, V),
	            translationMm(E, G),
	            translationMm(E, V),
	            translationMm(G, V),
	            translationMm(U, V),
	            rotationDeg(CPose3D(), G),
	            translationMm(CPose3D(), G),
	            nDiff > 0 ? nDiffEdge / nDiff : 0};
	return c;
}

}  // namespace bims::flow
