// bims-flow-check's logic (docs/flow.md): the pipeline (flow-only variant
// by default) over a rawlog and, for every frame with flow and ground truth
// on both sides, the flow labels of four relative poses
// (flow::checkPoseSources): a table line per frame on stdout, an optional
// CSV, the mean and median of every column, and an optional PNG strip of
// the used pose's Diff pixels in red over chosen frames.
#pragma once

#include <bims/flow/pose_check.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <opencv2/core.hpp>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace bims::apps
{
/** What bims-flow-check's command line gives (nullopt: not given). */
struct FlowCheckOptions
{
	std::string config;                ///< experiment .ini
	std::string rawlog;                ///< input rawlog
	std::string gt;                    ///< ground-truth TUM trajectory (T_WC)
	std::string frames;                ///< 3D-scan indices A:B ("": all)
	std::optional<std::string> csv;    ///< per-frame CSV
	std::optional<std::string> strip;  ///< PNG strip of Diff masks over RGB
	std::string stripFrames;  ///< comma-separated scan indices for strip
	std::string variant = "flow-only";  ///< pipeline variant
	bool progress = true;               ///< progress line on stderr
};

/** The first line on stdout: the columns of the per-frame table. */
const char* tableHeader();
/** One frame's line of the table (with its newline). */
std::string tableLine(size_t index, uint32_t flags,
                      const flow::PoseSourceCheck& c);
/** The first line of the CSV (with its newline). */
const char* csvHeader();
/** One frame's CSV line (with its newline). */
std::string csvLine(size_t index, uint32_t flags,
                    const flow::PoseSourceCheck& c);
/** The summary of \a rows (one PoseSourceCheck::values per frame, at
 * least one): a line "# mean over N frames:", then per column its name,
 * mean and median (the upper one for an even count). */
std::string summary(
    const std::vector<std::array<double, flow::PoseSourceCheck::kValues>>&
        rows);
/** A frame of the strip: the RGB image of \a scan (\a grey when it has
 * none of that size), its pixels of \a mask blended with red, "frame
 * \a index" written top left. */
cv::Mat stripTile(const mrpt::obs::CObservation3DRangeScan& scan,
                  const cv::Mat& grey, const cv::Mat& mask, size_t index);

/** bims-flow-check: checks the options (UsageError), runs and writes
 * everything; returns the exit code (0), errors are thrown. */
int runFlowCheck(const FlowCheckOptions& o);

}  // namespace bims::apps
