#include <bims/flow/consistency.h>
#include <bims/flow/flow_pose.h>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <stdexcept>

namespace bims::flow
{
cv::Mat labelConsistency(const cv::Mat& observed, const cv::Mat& expected,
                         const cv::Mat& depth, const mrpt::img::TCamera& cam,
                         const mrpt::poses::CPose3D& T_CprevC,
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
	const double tx = T_CprevC.x(), ty = T_CprevC.y();
	const double f = 0.5 * (cam.fx() + cam.fy());
	const double noiseGain = p.depth_noise_sigmas * f *
	                         std::sqrt(tx * tx + ty * ty) * p.depth_noise_a;
	const float W = static_cast<float>(depth.cols - 1);
	const float H = static_cast<float>(depth.rows - 1);
	// z <= max_depth_m (double) exactly as a float comparison: against the
	// largest float not above it. It also rejects NaN and +inf, z > 0 rejects
	// -inf; a non-finite flow fails the bounds tests below.
	float maxDepth = static_cast<float>(p.max_depth_m);
	if (static_cast<double>(maxDepth) > p.max_depth_m)
		maxDepth = std::nextafter(maxDepth, 0.0f);
	const double thr = p.diff_threshold_px + noiseGain;
	const double thr2 = thr * thr;
	cv::Mat edges;
	if (p.depth_edge_rel > 0)
		edges = depthEdgeMask(depth, p.depth_edge_rel, p.depth_edge_px);
	// The squared flow difference in float is within 2^-22 (relative) of the
	// double one: outside [lo, hi] the float comparison decides as the
	// double one would; inside it, and for the visibility gate, the pixel is
	// labelled in double (exactLabel).
	const float hi = static_cast<float>(thr2 * (1 + 1e-5));
	const float lo = static_cast<float>(thr2 * (1 - 1e-5));
	cv::Mat labels(depth.size(), CV_8SC1);
	LabelStats st;
	for (int v = 0; v < depth.rows; v++)
	{
		const float* zr = depth.ptr<float>(v);
		const float* o = observed.ptr<float>(v);
		const float* e = expected.ptr<float>(v);
		auto* l = labels.ptr<int8_t>(v);
		const cv::Vec3f* S = visible ? tensor->ptr<cv::Vec3f>(v) : nullptr;
		const float fv = static_cast<float>(v);
		// The definition, one pixel (depth edges apart).
		auto exactLabel = [&](int u) -> int8_t
		{
			const float z = zr[u];
			const float fu = static_cast<float>(u);
			const float e0 = e[2 * u], e1 = e[2 * u + 1];
			const float o0 = o[2 * u], o1 = o[2 * u + 1];
			const float eu = fu + e0, ev = fv + e1;
			const float ou = fu + o0, ov = fv + o1;
			// (the bounds also reject NaN and infinite flows)
			if (!(z > 0.0f && z <= maxDepth && eu >= 0 && ev >= 0 && eu <= W &&
			      ev <= H && ou >= 0 && ov >= 0 && ou <= W && ov <= H))
				return kNoLabel;
			const double du = o0 - e0, dv = o1 - e1;
			if (!(du * du + dv * dv > thr2)) return kNotDiff;
			// d^T S d: squared RMS intensity change d would cause
			if (S &&
			    du * du * S[u][0] + 2 * du * dv * S[u][1] + dv * dv * S[u][2] <
			        minChange2)
				return kNotDiff;
			return kDiff;
		};
		int u = 0;
#if CV_SIMD128
		const cv::v_float32x4 zero = cv::v_setall_f32(0.0f),
		                      vmax = cv::v_setall_f32(maxDepth),
		                      vW = cv::v_setall_f32(W),
		                      vH = cv::v_setall_f32(H),
		                      vfv = cv::v_setall_f32(fv),
		                      vhi = cv::v_setall_f32(hi),
		                      vlo = cv::v_setall_f32(lo),
		                      four = cv::v_setall_f32(4.0f);
		cv::v_float32x4 vu(0.0f, 1.0f, 2.0f, 3.0f);
		for (; u + 4 <= depth.cols; u += 4, vu += four)
		{
			const cv::v_float32x4 z = cv::v_load(zr + u);
			cv::v_float32x4 e0, e1, o0, o1;
			cv::v_load_deinterleave(e + 2 * u, e0, e1);
			cv::v_load_deinterleave(o + 2 * u, o0, o1);
			const cv::v_float32x4 eu = vu + e0, ev = vfv + e1;
			const cv::v_float32x4 ou = vu + o0, ov = vfv + o1;
			const cv::v_float32x4 ok = (z > zero) & (z <= vmax) & (eu >= zero) &
			                           (ev >= zero) & (eu <= vW) & (ev <= vH) &
			                           (ou >= zero) & (ov >= zero) &
			                           (ou <= vW) & (ov <= vH);
			const cv::v_float32x4 du = o0 - e0, dv = o1 - e1;
			const cv::v_float32x4 d2 = du * du + dv * dv;
			const int okBits = cv::v_signmask(ok);
			const int hiBits = cv::v_signmask(d2 > vhi) & okBits;
			const int midBits =
			    cv::v_signmask((d2 >= vlo) & (d2 <= vhi)) & okBits;
			const int exactBits = midBits | (S ? hiBits : 0);
			// kDiff = 1, kNotDiff = 0, kNoLabel = -1: hi + ok - 1
			for (int k = 0; k < 4; k++)
				l[u + k] = static_cast<int8_t>(((hiBits >> k) & 1) +
				                               ((okBits >> k) & 1) - 1);
			if (exactBits)
				for (int k = 0; k < 4; k++)
					if (exactBits & (1 << k)) l[u + k] = exactLabel(u + k);
		}
#endif
		for (; u < depth.cols; u++) l[u] = exactLabel(u);
		if (!edges.empty())
		{
			const uint8_t* ed = edges.ptr<uint8_t>(v);
			for (u = 0; u < depth.cols; u++)
				if (ed[u]) l[u] = kNoLabel;
		}
		size_t nDiff = 0, nNot = 0;
		for (u = 0; u < depth.cols; u++)
		{
			nDiff += l[u] == kDiff;
			nNot += l[u] == kNotDiff;
		}
		st.diff += nDiff;
		st.notDiff += nNot;
	}
	st.none = depth.total() - st.diff - st.notDiff;
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
