// OUTDIR/report.md of a bims-run: one short page a user reads first, with
// the run's figures (from its metrics.json), its scores when the input has
// ground truth beside it, and links to the files the run wrote.
#pragma once

#include <bims/io/image_file.h>

#include <string>
#include <vector>

namespace bims::apps
{
/** What the report says of the run besides metrics.json. */
struct RunReportInputs
{
	std::string outDir;                ///< the run's folder (metrics.json)
	std::vector<std::string> rawlogs;  ///< its inputs
	std::string config;                ///< the experiment .ini given
	std::string odometryMode;          ///< [odometry] mode (imu, vision)
	ImageLimits images;                ///< [input]: the masks' largest size
};

/** The report's Markdown: the run (status, variant, config, inputs),
 * frames and their egomotion flags, the IMU (samples read, not used, the
 * odometry mode), the speed (end to end and each stage's median and p95),
 * and, when the only input has ground truth beside it (IN_gt/, as bims-sim
 * and the importers write), the ATE and RPE of trajectory.txt and the
 * masks' precision, recall, F1 and IoU over every pixel of the frames both
 * have (labels of values 0 and 255 only; bims-eval masks --depth-valid
 * gives the figures over the pixels with depth); then links to the
 * outputs. Throws std::runtime_error when metrics.json is missing or not
 * JSON. */
std::string runReport(const RunReportInputs& in);

/** runReport written to OUTDIR/report.md (whole or not at all). */
void writeRunReport(const RunReportInputs& in);

}  // namespace bims::apps
