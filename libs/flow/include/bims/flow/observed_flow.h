// Dense observed optical flow between two grey images (OpenCV DIS or
// Farneback), backward convention: flow(u) = u_{t-1} - u_t on frame t's pixels.
#pragma once

#include <bims/flow/params.h>
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

#include <cmath>
#include <string>

namespace bims::flow
{
/** Scratch images of structureTensor(), kept between calls. */
struct TensorBuffers
{
	cv::Mat gx, gy, products;
};

/** [flow] dis_preset = auto: DIS "ultrafast" on images at least this wide,
 * "fast" on smaller ones (measured in docs/journal/optical-flow.md: at 640x480
 * ultrafast keeps the fused F1 within 0.003 of fast for 5 ms less CPU per
 * frame; at 320x240 it loses up to 0.07 of flow-only F1 and 0.009 fused). */
constexpr int kDisUltrafastMinWidth = 640;
/** The DIS preset ObservedFlow uses for \a preset on images \a width wide
 * (the images DIS sees: after [flow] downscale). */
DisPreset disPresetFor(DisPreset preset, int width);

/** Why the observed flow of \a p cannot run on width x height images:
 * "" when it can. DIS (OpenCV 4's) builds its pyramid from the image's
 * size down to the preset's finest scale; when the size does not reach
 * that scale OpenCV picks its scales from the width alone and reads
 * outside a short image (a crash, e.g. at 40 x 8 or 320 x 20), or fails
 * below 12 px. The images must reach it: at least patch x 2^finest pixels
 * on the shorter side and about 4 patch x 2^(finest - 1/2) on the longer
 * one (OpenCV 4.6's presets: 32 and 91 for ultrafast and fast, 16 and
 * 46 for medium), after [flow] downscale; the preset's patch size and
 * finest scale are asked of OpenCV. Farneback takes any size (downscale
 * px per side).
 * The message names the size, the least one and the keys. */
std::string observedFlowSizeProblem(const FlowParams& p, int width, int height);

class ObservedFlow
{
 public:
	explicit ObservedFlow(const FlowParams& p = {});

	/** Backward flow of \a cur (frame t) towards \a prev (frame t-1), both
	 * CV_8UC1 of the same size. Returns CV_32FC2 of that size. Throws
	 * std::invalid_argument on empty or mismatched images, and on images
	 * too small for the method (observedFlowSizeProblem). */
	cv::Mat compute(const cv::Mat& prev, const cv::Mat& cur);

	/** The same flow, measured after derotation: \a prev is first warped
	 * by the homography \a H_prev_cur (a current pixel u maps to H u in
	 * \a prev; rotationHomography() of the egomotion's rotation), so that
	 * DIS only has to find the residual r of the translation and of the
	 * rotation's error; the result is composed back, flow(u) =
	 * H (u + r(u)) - u. Large camera rotations (tens of pixels per frame)
	 * otherwise exceed what the coarse-to-fine search recovers. Pixels whose
	 * H u leaves \a prev see a replicated border there: their flow leaves
	 * the image and the labels skip them. */
	cv::Mat computeDerotated(const cv::Mat& prev, const cv::Mat& cur,
	                         const cv::Matx33d& H_prev_cur);

	/** Structure tensor of the last \a cur (structureTensor()), computed by
	 * compute() when [flow] visible_change_grey > 0 or refine_pose is
	 * enabled; empty otherwise. Each compute() makes a new one: a copy of
	 * the cv::Mat taken before keeps its data (as the returned flows). */
	const cv::Mat& tensor() const { return tensor_; }

 private:
	FlowParams p_;
	cv::Mat tensor_;
	/** The tensor before, whose memory the next one reuses when nobody
	 * else holds it any more. */
	cv::Mat spareTensor_;
	TensorBuffers tensorBuf_;  ///< scratch, reused
	cv::Mat warped_;           ///< scratch: prev derotated, reused
	cv::Ptr<cv::DISOpticalFlow> dis_;
	DisPreset disPreset_ = DisPreset::Auto;  ///< the preset dis_ has
};

/** The flow of a derotated measurement composed back: for the residual flow
 * r (CV_32FC2) measured against the image warped by \a H,
 * flow(u) = H (u + r(u)) - u (dehomogenised; NaN where the third coordinate
 * is not positive). \a flow may be \a residual (in place). */
void composeWithHomography(const cv::Mat& residual, const cv::Matx33d& H,
                           cv::Mat& flow);

/** Local structure tensor of a grey image (CV_8UC1): per pixel the window
 * means of Ix^2, Ix Iy, Iy^2 (gradients in grey levels per pixel, Sobel),
 * over a \a window x \a window box. CV_32FC3. For a flow difference d,
 * sqrt(d^T S d) is the RMS intensity change d would cause in the window:
 * whether the observed flow can tell d at all (aperture, textureless
 * surfaces). */
cv::Mat structureTensor(const cv::Mat& grey, int window);

/** structureTensor() into \a out (its data reused when its size and type
 * fit, as cv::Mat::create), with \a buf as scratch. */
void structureTensor(const cv::Mat& grey, int window, cv::Mat& out,
                     TensorBuffers& buf);

/** Smaller eigenvalue of a structure tensor pixel (Sxx, Sxy, Syy). */
inline float minEigen(const cv::Vec3f& s)
{
	const float h = 0.5f * (s[0] - s[2]);
	return 0.5f * (s[0] + s[2]) - std::sqrt(h * h + s[1] * s[1]);
}

}  // namespace bims::flow
