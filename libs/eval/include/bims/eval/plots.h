// PNG plots drawn with OpenCV (no GUI needed).
#pragma once

#include <bims/common/trajectory.h>
#include <bims/eval/association.h>

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace bims::eval
{
/** Trajectory figure: top view (x-y) and side view (x-z) of the ground truth
 * (black) and the aligned estimate (red), grey lines joining associated
 * poses, a legend, a scale bar in metres and \a title. \a pairs index
 * (gt, estAligned) as in AteResult::pairs (may be empty). */
cv::Mat plotTrajectories(const Trajectory& gt, const Trajectory& estAligned,
                         const IndexPairs& pairs, const std::string& title);

/** The images side by side, each scaled by \a scale (INTER_AREA), in one
 * row (a strip of frames). All must have the same size and type; throws
 * std::invalid_argument otherwise or when there is none. */
cv::Mat imageStrip(const std::vector<cv::Mat>& images, double scale);

/** Writes an image; throws std::runtime_error naming the file on failure. */
void writePng(const std::string& path, const cv::Mat& img);

}  // namespace bims::eval
