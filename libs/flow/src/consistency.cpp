#include <bims/flow/consistency.h>
#include <bims/flow/flow_pose.h>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <stdexcept>

namespace bims::flow
{
cv::Mat labelConsistency(const cv::Mat& observed, const cv::Mat& expected,
                         const cv::Mat& depth, const mrpt::img::TCamera& cam,
                         const mrpt::poses::CPose3D& T_prev_cur,
                         const FlowParams& p, LabelStats* stats,
                         const cv::Mat* tensor)
{
	if (observed.type() != CV_32FC2 || expected.type() != CV_32FC2 ||
	    depth.type() != CV_32FC1 || observed.size() != expected.size() ||
	    observed.size() != depth.size())
		throw std::invalid_argument(
		    "labelConsistency: need CV_32FC2 flows and CV_32FC1 depth of one "
		    "size");
	const bool visible = p.visible_change_grey > 0;
	if (visible && (!tensor || tensor->type() != CV_32FC3 ||
	                tensor->size() != depth.size()))
		throw std::invalid_argument(
		    "labelConsistency: visible_change_grey needs the current image's "
		    "structure tensor (CV_32FC3 of the depth's size)");
	const double minChange2 = p.visible_change_grey * p.visible_change_grey;
	const double tx = T_prev_cur.x(), ty = T_prev_cur.y();
	const double f = 0.5 * (cam.fx() + cam.fy());
	const double noiseGain = p.depth_noise_sigmas * f *
	                         std::sqrt(tx * tx + ty * ty) * p.depth_noise_a;
	const float W = static_cast<float>(depth.cols - 1);
	const float H = static_cast<float>(depth.rows - 1);
	cv::Mat edges;
	if (p.depth_edge_rel > 0)
		edges = depthEdgeMask(depth, p.depth_edge_rel, p.depth_edge_px);
	cv::Mat labels(depth.size(), CV_8SC1);
	LabelStats st;
	for (int v = 0; v < depth.rows; v++)
	{
		const float* zr = depth.ptr<float>(v);
		const auto* o = observed.ptr<cv::Vec2f>(v);
		const auto* e = expected.ptr<cv::Vec2f>(v);
		auto* l = labels.ptr<int8_t>(v);
		const uint8_t* ed = edges.empty() ? nullptr : edges.ptr<uint8_t>(v);
		const cv::Vec3f* S = visible ? tensor->ptr<cv::Vec3f>(v) : nullptr;
		for (int u = 0; u < depth.cols; u++)
		{
			const float z = zr[u];
			int8_t lab = kNoLabel;
			if (std::isfinite(z) && z > 0.0f && z <= p.max_depth_m &&
			    !(ed && ed[u]) && std::isfinite(e[u][0]) &&
			    std::isfinite(e[u][1]) && std::isfinite(o[u][0]) &&
			    std::isfinite(o[u][1]))
			{
				const float eu = u + e[u][0], ev = v + e[u][1];
				const float ou = u + o[u][0], ov = v + o[u][1];
				if (eu >= 0 && ev >= 0 && eu <= W && ev <= H && ou >= 0 &&
				    ov >= 0 && ou <= W && ov <= H)
				{
					// sigma of the expected flow from depth noise: f |t_xy| a
					// z^2 / z^2
					const double thr = p.diff_threshold_px + noiseGain;
					const double du = o[u][0] - e[u][0], dv = o[u][1] - e[u][1];
					lab = (du * du + dv * dv > thr * thr) ? kDiff : kNotDiff;
					// d^T S d: squared RMS intensity change d would cause
					if (lab == kDiff && S &&
					    du * du * S[u][0] + 2 * du * dv * S[u][1] +
					            dv * dv * S[u][2] <
					        minChange2)
						lab = kNotDiff;
				}
			}
			l[u] = lab;
			if (lab == kDiff)
				st.diff++;
			else if (lab == kNotDiff)
				st.notDiff++;
			else
				st.none++;
		}
	}
	if (stats) *stats = st;
	return labels;
}

cv::Mat flowToColor(const cv::Mat& flow, double maxMagPx)
{
	CV_Assert(flow.type() == CV_32FC2);
	cv::Mat hsv(flow.size(), CV_8UC3);
	for (int v = 0; v < flow.rows; v++)
	{
		const auto* f = flow.ptr<cv::Vec2f>(v);
		auto* h = hsv.ptr<cv::Vec3b>(v);
		for (int u = 0; u < flow.cols; u++)
		{
			if (!std::isfinite(f[u][0]) || !std::isfinite(f[u][1]))
			{
				h[u] = {0, 0, 0};
				continue;
			}
			const double mag = std::hypot(f[u][0], f[u][1]);
			const double ang = std::atan2(f[u][1], f[u][0]);  // [-pi, pi]
			const int hue = static_cast<int>((ang + M_PI) / (2 * M_PI) * 179.0);
			const int val =
			    static_cast<int>(std::min(1.0, mag / maxMagPx) * 255.0);
			h[u] = {static_cast<uchar>(hue), 255, static_cast<uchar>(val)};
		}
	}
	cv::Mat bgr;
	cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
	return bgr;
}

cv::Mat labelsToColor(const cv::Mat& labels)
{
	CV_Assert(labels.type() == CV_8SC1);
	cv::Mat out(labels.size(), CV_8UC3);
	for (int v = 0; v < labels.rows; v++)
	{
		const auto* l = labels.ptr<int8_t>(v);
		auto* o = out.ptr<cv::Vec3b>(v);
		for (int u = 0; u < labels.cols; u++)
			o[u] = l[u] == kDiff      ? cv::Vec3b(0, 0, 255)
			       : l[u] == kNotDiff ? cv::Vec3b(128, 128, 128)
			                          : cv::Vec3b(0, 0, 0);
	}
	return out;
}

}  // namespace bims::flow
