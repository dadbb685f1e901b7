// PNG plots drawn with OpenCV (no GUI needed).
#pragma once

#include <bims/eval/association.h>
#include <bims/io/trajectory.h>

#include <opencv2/core.hpp>

#include <optional>
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

/** Values drawn as bars in groups: one group per category along the
 * horizontal axis, one bar per series in each group (a colour each, named in
 * the legend). */
struct GroupedBars
{
	std::string title;
	std::string yLabel;  ///< the vertical axis (the values' name and unit)
	std::string xLabel;  ///< what the groups are
	/** One label per group; '\n' breaks it into lines under the group. */
	std::vector<std::string> groups;
	std::vector<std::string> series;  ///< legend entries
	/** values[group][series]; NaN: no value (drawn as a red x on the axis,
	 * explained in the legend by missingLabel). */
	std::vector<std::vector<double>> values;
	std::string missingLabel = "no value";
	/** The top of the vertical axis when the values have one (a score or
	 * a share: 1); none: from the values. */
	std::optional<double> yMax;
};

/** Bar chart of \a c: white background, y axis from 0 (or the lowest
 * value, when negative) to c.yMax or a little above the highest value, with
 * ticks at 1, 2 or 5 times a power of ten, the
 * value above each bar, the group labels under the axis, legend top right.
 * 1024 x 640 pixels, wider (never narrower) when the groups and their
 * labels need more room. Throws std::invalid_argument when values does not
 * hold one row per group and one value per series. */
cv::Mat plotGroupedBars(const GroupedBars& c);

/** Writes an image; throws std::runtime_error naming the file on failure. */
void writePng(const std::string& path, const cv::Mat& img);

}  // namespace bims::eval
