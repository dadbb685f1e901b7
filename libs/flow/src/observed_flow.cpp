#include <bims/flow/observed_flow.h>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace bims::flow
{
namespace
{
/** Whether \a m is the only cv::Mat header referencing its data (the count
 * is changed atomically by every copy and release, on any thread). */
bool soleReference(const cv::Mat& m)
{
	return m.u && __atomic_load_n(&m.u->refcount, __ATOMIC_ACQUIRE) == 1 &&
	       __atomic_load_n(&m.u->urefcount, __ATOMIC_ACQUIRE) == 0;
}
}  // namespace

DisPreset disPresetFor(DisPreset preset, int width)
{
	if (preset != DisPreset::Auto) return preset;
	return width >= kDisUltrafastMinWidth ? DisPreset::Ultrafast
	                                      : DisPreset::Fast;
}

namespace
{
int disCode(DisPreset preset)
{
	return preset == DisPreset::Ultrafast ? cv::DISOpticalFlow::PRESET_ULTRAFAST
	       : preset == DisPreset::Medium  ? cv::DISOpticalFlow::PRESET_MEDIUM
	                                      : cv::DISOpticalFlow::PRESET_FAST;
}

/** A DIS preset's patch size and finest scale, as OpenCV sets them. */
struct DisScales
{
	int patch = 8, finest = 2;
};
DisScales disScales(DisPreset preset)
{
	static const std::array<DisScales, 3> table = []
	{
		std::array<DisScales, 3> t;
		for (DisPreset p :
		     {DisPreset::Ultrafast, DisPreset::Fast, DisPreset::Medium})
		{
			const auto dis = cv::DISOpticalFlow::create(disCode(p));
			t[static_cast<size_t>(p) - 1] = {dis->getPatchSize(),
			                                 dis->getFinestScale()};
		}
		return t;
	}();
	return table[static_cast<size_t>(preset) - 1];
}

/** The coarsest scale OpenCV's DIS computes for a w x h image (its own
 * expression, DISOpticalFlowImpl::calc). */
int disCoarsestScale(int w, int h, int patch)
{
	return std::min(
	    static_cast<int>(
	        std::log(std::max(w, h) / (4.0 * patch)) / std::log(2.0) + 0.5),
	    static_cast<int>(std::log(std::min(w, h) / double(patch)) /
	                     std::log(2.0)));
}
}  // namespace

std::string observedFlowSizeProblem(const FlowParams& p, int width, int height)
{
	const int d = std::max(1, p.downscale);
	const int w = width / d, h = height / d;
	const std::string size =
	    std::to_string(width) + "x" + std::to_string(height);
	const std::string scaled =
	    d > 1 ? " (" + std::to_string(w) + "x" + std::to_string(h) +
	                " after [flow] downscale " + std::to_string(d) + ")"
	          : std::string();
	if (p.method != FlowMethod::Dis)
		return w >= 1 && h >= 1
		           ? std::string()
		           : size +
		                 " is too small for the observed flow: [flow] "
		                 "downscale " +
		                 std::to_string(d) + " leaves no pixel";
	const DisPreset preset = disPresetFor(p.dis_preset, w);
	const DisScales s = disScales(preset);
	if (w >= 1 && h >= 1 && disCoarsestScale(w, h, s.patch) >= s.finest)
		return {};
	// the least shorter side, and the least longer side with it
	const int shorter = s.patch << s.finest;
	int longer = shorter;
	while (disCoarsestScale(longer, shorter, s.patch) < s.finest) ++longer;
	const char* name = preset == DisPreset::Ultrafast ? "ultrafast"
	                   : preset == DisPreset::Medium  ? "medium"
	                                                  : "fast";
	return size + scaled +
	       " is too small for the observed flow (OpenCV's DIS, preset " + name +
	       "): it needs at least " + std::to_string(shorter * d) +
	       " pixels on the shorter side and " + std::to_string(longer * d) +
	       " on the longer one" +
	       (d > 1 ? " at [flow] downscale " + std::to_string(d) : "") +
	       " ([flow] method = farneback takes any size)";
}

ObservedFlow::ObservedFlow(const FlowParams& p) : p_(p)
{
	// (DIS is created by the first compute(): "auto" depends on the width)
	if (p_.downscale < 1)
		throw std::invalid_argument("observed flow: downscale must be >= 1");
}

cv::Mat ObservedFlow::compute(const cv::Mat& prev, const cv::Mat& cur)
{
	if (prev.empty() || cur.empty() || prev.size() != cur.size() ||
	    prev.type() != CV_8UC1 || cur.type() != CV_8UC1)
		throw std::invalid_argument(
		    "observed flow: need two non-empty CV_8UC1 images of one size");
	if (const std::string why = observedFlowSizeProblem(p_, cur.cols, cur.rows);
	    !why.empty())
		throw std::invalid_argument("observed flow: " + why);
	// The last tensor may still be held by the caller (the pipeline keeps it
	// for its frame while the next flow runs): it becomes the spare, and the
	// one before it is written again only if nobody else holds it.
	std::swap(tensor_, spareTensor_);
	if (!soleReference(tensor_)) tensor_.release();
	if (p_.visible_change_grey > 0 || p_.refine_pose != RefinePose::None)
		structureTensor(cur, p_.texture_window_px, tensor_, tensorBuf_);
	else
		tensor_.release();
	cv::Mat a = cur, b = prev;
	if (p_.downscale > 1)
	{
		const cv::Size s(cur.cols / p_.downscale, cur.rows / p_.downscale);
		cv::resize(cur, a, s, 0, 0, cv::INTER_AREA);
		cv::resize(prev, b, s, 0, 0, cv::INTER_AREA);
	}
	cv::Mat flow;
	if (p_.method == FlowMethod::Dis)
	{
		const DisPreset preset = disPresetFor(p_.dis_preset, a.cols);
		if (!dis_ || preset != disPreset_)
		{
			dis_ = cv::DISOpticalFlow::create(disCode(preset));
			disPreset_ = preset;
		}
		dis_->calc(a, b, flow);
	}
	else
		cv::calcOpticalFlowFarneback(a, b, flow, 0.5, 4, 15, 3, 5, 1.1, 0);
	if (p_.downscale > 1)
	{
		cv::Mat up;
		cv::resize(flow, up, cur.size(), 0, 0, cv::INTER_LINEAR);
		up *= static_cast<double>(p_.downscale);
		flow = up;
	}
	return flow;
}

cv::Mat ObservedFlow::computeDerotated(const cv::Mat& prev, const cv::Mat& cur,
                                       const cv::Matx33d& H)
{
	if (prev.empty() || prev.size() != cur.size())
		throw std::invalid_argument(
		    "observed flow: need two non-empty CV_8UC1 images of one size");
	// warped(u) = prev(H u)
	cv::warpPerspective(prev, warped_, H, prev.size(),
	                    cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
	                    cv::BORDER_REPLICATE);
	cv::Mat flow = compute(warped_, cur);
	composeWithHomography(flow, H, flow);
	return flow;
}

void composeWithHomography(const cv::Mat& residual, const cv::Matx33d& H,
                           cv::Mat& flow)
{
	if (residual.type() != CV_32FC2)
		throw std::invalid_argument(
		    "composeWithHomography: the residual must be CV_32FC2");
	flow.create(residual.size(), CV_32FC2);
	constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
	// In float: |H (u + r)| is at most a few thousand px, so each product
	// and sum rounds by < 1e-4 px and the dehomogenised flow stays within
	// 1e-3 px of the double-precision formula (tested).
	const float h00 = static_cast<float>(H(0, 0)),
	            h01 = static_cast<float>(H(0, 1)),
	            h10 = static_cast<float>(H(1, 0)),
	            h11 = static_cast<float>(H(1, 1)),
	            h20 = static_cast<float>(H(2, 0)),
	            h21 = static_cast<float>(H(2, 1));
	for (int v = 0; v < flow.rows; v++)
	{
		const float* r = residual.ptr<float>(v);
		float* f = flow.ptr<float>(v);
		// H (u, v, 1) along the row: the constant part once per row
		const float X0 = static_cast<float>(H(0, 1) * v + H(0, 2));
		const float Y0 = static_cast<float>(H(1, 1) * v + H(1, 2));
		const float Z0 = static_cast<float>(H(2, 1) * v + H(2, 2));
		const float fv = static_cast<float>(v);
		// In place: r[2u..] is read before f[2u..] is written.
		int u = 0;
#if CV_SIMD128
		const cv::v_float32x4 vh00 = cv::v_setall_f32(h00),
		                      vh01 = cv::v_setall_f32(h01),
		                      vh10 = cv::v_setall_f32(h10),
		                      vh11 = cv::v_setall_f32(h11),
		                      vh20 = cv::v_setall_f32(h20),
		                      vh21 = cv::v_setall_f32(h21);
		const cv::v_float32x4 vX0 = cv::v_setall_f32(X0),
		                      vY0 = cv::v_setall_f32(Y0),
		                      vZ0 = cv::v_setall_f32(Z0),
		                      vfv = cv::v_setall_f32(fv),
		                      vmin = cv::v_setall_f32(1e-12f),
		                      one = cv::v_setall_f32(1.0f),
		                      nan = cv::v_setall_f32(kNaN),
		                      four = cv::v_setall_f32(4.0f);
		cv::v_float32x4 vu(0.0f, 1.0f, 2.0f, 3.0f);
		for (; u + 4 <= flow.cols; u += 4, vu += four)
		{
			cv::v_float32x4 rx, ry;
			cv::v_load_deinterleave(r + 2 * u, rx, ry);
			const cv::v_float32x4 x = vu + rx;
			const cv::v_float32x4 X = vX0 + vh00 * x + vh01 * ry;
			const cv::v_float32x4 Y = vY0 + vh10 * x + vh11 * ry;
			const cv::v_float32x4 Z = vZ0 + vh20 * x + vh21 * ry;
			const cv::v_float32x4 ok = Z > vmin;
			const cv::v_float32x4 iZ = one / cv::v_select(ok, Z, one);
			cv::v_store_interleave(f + 2 * u,
			                       cv::v_select(ok, X * iZ - vu, nan),
			                       cv::v_select(ok, Y * iZ - vfv, nan));
		}
#endif
		for (; u < flow.cols; u++)
		{
			const float fu = static_cast<float>(u);
			const float x = fu + r[2 * u], ry = r[2 * u + 1];
			const float X = X0 + h00 * x + h01 * ry;
			const float Y = Y0 + h10 * x + h11 * ry;
			const float Z = Z0 + h20 * x + h21 * ry;
			const bool ok = Z > 1e-12f;
			const float iZ = 1.0f / (ok ? Z : 1.0f);
			f[2 * u] = ok ? X * iZ - fu : kNaN;
			f[2 * u + 1] = ok ? Y * iZ - fv : kNaN;
		}
	}
}

namespace
{
// Box sums of the unscaled Sobel products (|gradient| <= 4 * 255 = 1020 grey
// levels, 8x the gradient) fit an int32 up to this window side.
constexpr int kMaxExactWindow = 45;
}  // namespace

void structureTensor(const cv::Mat& grey, int window, cv::Mat& out,
                     TensorBuffers& buf)
{
	if (grey.empty() || grey.type() != CV_8UC1)
		throw std::invalid_argument("structureTensor: need a CV_8UC1 image");
	if (window < 1)
		throw std::invalid_argument("structureTensor: window must be >= 1");
	// Both 3x3 Sobel gradients in one pass, 8x the gradient in grey levels
	// per pixel, exact in int16 (border reflected, 101).
	cv::spatialGradient(grey, buf.gx, buf.gy, 3, cv::BORDER_DEFAULT);
	const bool exact = window <= kMaxExactWindow;
	buf.products.create(grey.size(), exact ? CV_32SC3 : CV_32FC3);
	// gx², gx gy, gy² per pixel, in int32 (exact sums) or float
	auto products = [&](auto* p, const int16_t* gx, const int16_t* gy)
	{
		using T = std::remove_pointer_t<decltype(p)>;
		for (int u = 0; u < grey.cols; u++)
		{
			const T x = gx[u], y = gy[u];
			p[3 * u] = x * x;
			p[3 * u + 1] = x * y;
			p[3 * u + 2] = y * y;
		}
	};
	for (int v = 0; v < grey.rows; v++)
	{
		const int16_t* gx = buf.gx.ptr<int16_t>(v);
		const int16_t* gy = buf.gy.ptr<int16_t>(v);
		if (exact)
			products(buf.products.ptr<int32_t>(v), gx, gy);
		else
			products(buf.products.ptr<float>(v), gx, gy);
	}
	// One box filter over the three products: exact integer sums, then the
	// window mean in float. The Sobel's 8x: 1/64, a power of two (exact).
	cv::boxFilter(buf.products, out, CV_32F, {window, window}, {-1, -1}, true,
	              cv::BORDER_REFLECT);
	out *= 1.0 / 64;
}

cv::Mat structureTensor(const cv::Mat& grey, int window)
{
	TensorBuffers buf;
	cv::Mat out;
	structureTensor(grey, window, out, buf);
	return out;
}

}  // namespace bims::flow
