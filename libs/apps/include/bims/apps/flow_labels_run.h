// bims-flow-labels' run (docs/flow.md): the labels of one RGB-D image pair
// (flow::labelPair) from its command line, written as colour pictures with
// per-stage timings. The program's main only reads its command line into
// FlowLabelsOptions and calls runFlowLabels.
#pragma once

#include <bims/flow/pair_labels.h>
#include <mrpt/poses/CPose3D.h>

#include <optional>
#include <string>

namespace bims::apps
{
/** What bims-flow-labels' command line gives (nullopt: not given). */
struct FlowLabelsOptions
{
	std::string rgb0;                   ///< previous RGB image
	std::string rgb1;                   ///< current RGB image
	std::string depth1;                 ///< current depth (16-bit PNG)
	std::string out;                    ///< output folder
	std::optional<std::string> config;  ///< experiment .ini ([flow], [input])
	double depth_scale = 5000.0;        ///< depth units per metre
	double fx = 0, fy = 0;    ///< focal lengths [px] (<= 0: the default)
	double cx = -1, cy = -1;  ///< principal point [px] (< 0: the centre)
	std::string pose = "0 0 0 0 0 0";  ///< T_C0C1 'x y z yaw pitch roll'
};

/** The pose 'x y z yaw pitch roll' (metres, degrees) of --pose; throws
 * UsageError unless it starts with 6 numbers. */
mrpt::poses::CPose3D parsePoseXyzYpr(const std::string& text);

/** bims-flow-labels: checks the options (no output may be an input), reads
 * the config and the images, labels the pair, writes observed_flow.png,
 * expected_flow.png, labels.png and overlay.png into the output folder and
 * prints the counts and timings on stdout. Returns the program's exit code
 * (0); errors are thrown. */
int runFlowLabels(const FlowLabelsOptions& o);

}  // namespace bims::apps
