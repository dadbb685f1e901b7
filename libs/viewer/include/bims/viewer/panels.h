// The 2D panels of the viewer as BGR images (CV_8UC3), independent of any
// GUI toolkit: RGB with the moving mask over it, depth, flow fields, labels.
#pragma once

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <opencv2/core.hpp>
#include <string>

namespace bims::viewer
{
/** The scan's intensity image as BGR (grey images are expanded); an empty
 * Mat when the scan has none. */
cv::Mat intensityBgr(const mrpt::obs::CObservation3DRangeScan& scan);

/** \a bgr with the pixels where \a mask != 0 tinted red (alpha 0.5) and the
 * mask outline drawn. \a mask may be empty (no overlay) and is resized
 * (nearest) when its size differs. */
cv::Mat overlayMask(const cv::Mat& bgr, const cv::Mat& mask);

/** Depth [m] of the scan coloured with a jet map over [0, maxDepthM]
 * (invalid = black). maxDepthM <= 0: the 99th percentile of valid depths. */
cv::Mat depthColour(const mrpt::obs::CObservation3DRangeScan& scan,
                    double maxDepthM = 0);

/** A CV_32FC2 flow field [px] in the usual HSV colour code (hue = direction,
 * value = magnitude / maxMagPx, saturated), NaN = black. maxMagPx <= 0:
 * the 99th percentile of magnitudes. Empty input -> grey image of
 * \a size (CV_8UC3). */
cv::Mat flowColour(const cv::Mat& flow, double maxMagPx, cv::Size size);

/** Flow labels (CV_8SC1: -1 none, 0 notDiff, 1 Diff) over a dimmed grey
 * copy of \a bgr: Diff red, notDiff green, none unchanged. */
cv::Mat labelsColour(const cv::Mat& labels, const cv::Mat& bgr);

/** A grey panel of \a size saying why there is no image (\a why, one short
 * line, centred). */
cv::Mat placeholderPanel(cv::Size size, const std::string& why);

/** Fractions of the pixels of a BGR image whose colour is, by hue, the
 * tier-0 blue, tier-1 yellow or tier-2 red of the 3D view (saturation and
 * value > 90 of 255, so shading by the lights still counts; grey
 * background, white and black never do). */
struct TierColours
{
	double blue = 0, yellow = 0, red = 0;
};
TierColours tierColourFractions(const cv::Mat& bgr);

}  // namespace bims::viewer
