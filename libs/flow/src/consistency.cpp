#include <bims/flow/consistency.h>
#include <bims/flow/flow_pose.h>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <stdexcept>

namespace bims::flow
{
namespace
{
void checkConsistencyInputs(const cv::Mat& observed, const cv::Mat& expected,
                            const cv::Mat& depth, const FlowParams& p,
                            const cv::Mat* tensor)
{
	if (observed.type() != CV_32FC2 || expected.type() != CV_32FC2 ||
	    depth.type() != CV_32FC1 || observed.size() != expected.size() ||
	    observed.size() != depth.size())
		throw std::invalid_argument(
		    "labelConsistency: need CV_32FC2 flows and CV_32FC1 depth of one "
		    "size");
	if (p.visible_change_grey > 0 && (!tensor || tensor->type() != CV_32FC3 ||
	                                  tensor->size() != depth.size()))
		throw std::invalid_argument(
		    "labelConsistency: visible_change_grey needs the current image's "
		    "structure tensor (CV_32FC3 of the depth's size)");
}

/** The per-pixel rule's constants for one frame. */
struct ConsistencyRule
{
	float maxDepth;     ///< z <= max_depth_m, as a float comparison
	float W, H;         ///< the largest pixel coordinates
	double thr2;        ///< squared threshold of the flow difference [px^2]
	double minChange2;  ///< squared visible change (0: no gate)
	float lo, hi;       ///< thr2's float bounds (see consistencyRule())
};

ConsistencyRule consistencyRule(const cv::Mat& depth,
                                const mrpt::img::TCamera& cam,
                                const mrpt::poses::CPose3D& T_CprevC,
                                const FlowParams& p)
{
	ConsistencyRule r;
	r.minChange2 = p.visible_change_grey * p.visible_change_grey;
	const double tx = T_CprevC.x(), ty = T_CprevC.y();
	const double f = 0.5 * (cam.fx() + cam.fy());
	const double noiseGain = p.depth_noise_sigmas * f *
	                         std::sqrt(tx * tx + ty * ty) * p.depth_noise_a;
	r.W = static_cast<float>(depth.cols - 1);
	r.H = static_cast<float>(depth.rows - 1);
	// z <= max_depth_m (double) exactly as a float comparison: against the
	// largest float not above it. It also rejects NaN and +inf, z > 0 rejects
	// -inf; a non-finite flow fails the bounds tests below.
	r.maxDepth = static_cast<float>(p.max_depth_m);
	if (static_cast<double>(r.maxDepth) > p.max_depth_m)
		r.maxDepth = std::nextafter(r.maxDepth, 0.0f);
	const double thr = p.diff_threshold_px + noiseGain;
	r.thr2 = thr * thr;
	// The squared flow difference in float is within 2^-22 (relative) of the
	// double one: outside [lo, hi] the float comparison decides as the
	// double one would; inside it, and for the visibility gate, the pixel is
	// labelled in double (ConsistencyRow::exact).
	r.hi = static_cast<float>(r.thr2 * (1 + 1e-5));
	r.lo = static_cast<float>(r.thr2 * (1 - 1e-5));
	return r;
}

/** One row of the inputs. */
struct ConsistencyRow
{
	const ConsistencyRule& r;
	const float* zr;     ///< depth
	const float* o;      ///< observed flow (u, v interleaved)
	const float* e;      ///< expected flow
	const cv::Vec3f* S;  ///< structure tensor (nullptr: no gate)
	float fv;            ///< the row's index

	/** The definition, one pixel (depth edges apart). */
	int8_t exact(int u) const
	{
		const float z = zr[u];
		const float fu = static_cast<float>(u);
		const float e0 = e[2 * u], e1 = e[2 * u + 1];
		const float o0 = o[2 * u], o1 = o[2 * u + 1];
		const float eu = fu + e0, ev = fv + e1;
		const float ou = fu + o0, ov = fv + o1;
		// (the bounds also reject NaN and infinite flows)
		if (!(z > 0.0f && z <= r.maxDepth && eu >= 0 && ev >= 0 && eu <= r.W &&
		      ev <= r.H && ou >= 0 && ov >= 0 && ou <= r.W && ov <= r.H))
			return kNoLabel;
		const double du = o0 - e0, dv = o1 - e1;
		if (!(du * du + dv * dv > r.thr2)) return kNotDiff;
		// d^T S d: squared RMS intensity change d would cause
		if (S && du * du * S[u][0] + 2 * du * dv * S[u][1] + dv * dv * S[u][2] <
		             r.minChange2)
			return kNotDiff;
		return kDiff;
	}

	/** Labels the pixels of the row four at a time where the float
	 * comparison decides (exact() where it may not); returns the first
	 * pixel left for exact(). */
	int labelFast(int8_t* l, int cols) const
	{
		int u = 0;
#if CV_SIMD128
		const cv::v_float32x4 zero = cv::v_setall_f32(0.0f),
		                      vmax = cv::v_setall_f32(r.maxDepth),
		                      vW = cv::v_setall_f32(r.W),
		                      vH = cv::v_setall_f32(r.H),
		                      vfv = cv::v_setall_f32(fv),
		                      vhi = cv::v_setall_f32(r.hi),
		                      vlo = cv::v_setall_f32(r.lo),
		                      four = cv::v_setall_f32(4.0f);
		cv::v_float32x4 vu(0.0f, 1.0f, 2.0f, 3.0f);
		for (; u + 4 <= cols; u += 4, vu += four)
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
					if (exactBits & (1 << k)) l[u + k] = exact(u + k);
		}
#else
		(void)l;
		(void)cols;
#endif
		return u;
	}
};

/** No label on depth edges (\a ed: the row of the edge mask, nullptr if
 * none), then the row's labels counted into \a st. */
void finishConsistencyRow(int8_t* l, const uint8_t* ed, int cols,
                          LabelStats& st)
{
	if (ed)
		for (int u = 0; u < cols; u++)
			if (ed[u]) l[u] = kNoLabel;
	size_t nDiff = 0, nNot = 0;
	for (int u = 0; u < cols; u++)
	{
		nDiff += l[u] == kDiff;
		nNot += l[u] == kNotDiff;
	}
	st.diff += nDiff;
	st.notDiff += nNot;
}
}  // namespace

cv::Mat labelConsistency(const cv::Mat& observed, const cv::Mat& expected,
                         const cv::Mat& depth, const mrpt::img::TCamera& cam,
                         const mrpt::poses::CPose3D& T_CprevC,
                         const FlowParams& p, LabelStats* stats,
                         const cv::Mat* tensor)
{
	checkConsistencyInputs(observed, expected, depth, p, tensor);
	const bool visible = p.visible_change_grey > 0;
	const ConsistencyRule rule = consistencyRule(depth, cam, T_CprevC, p);
	cv::Mat edges;
	if (p.depth_edge_rel > 0)
		edges = depthEdgeMask(depth, p.depth_edge_rel, p.depth_edge_px);
	cv::Mat labels(depth.size(), CV_8SC1);
	LabelStats st;
	for (int v = 0; v < depth.rows; v++)
	{
		const ConsistencyRow row{rule,
		                         depth.ptr<float>(v),
		                         observed.ptr<float>(v),
		                         expected.ptr<float>(v),
		                         visible ? tensor->ptr<cv::Vec3f>(v) : nullptr,
		                         static_cast<float>(v)};
		auto* l = labels.ptr<int8_t>(v);
		for (int u = row.labelFast(l, depth.cols); u < depth.cols; u++)
			l[u] = row.exact(u);
		finishConsistencyRow(l, edges.empty() ? nullptr : edges.ptr<uint8_t>(v),
		                     depth.cols, st);
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
