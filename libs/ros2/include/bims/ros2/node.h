// bims-ros2's node (docs/ros2.md): a DDS participant that reads a RGB-D
// camera's ROS 2 topics ([ros2]: depth, colour, camera info, IMU), runs the
// pipeline on the frames as they arrive (pipeline::LiveSegmentation, the
// same frames, poses and masks as bims-run on the same observations) and
// publishes each frame's moving mask, odometry and moving points. Frames
// that arrive while [ros2] queue_frames wait are dropped, oldest first,
// counted and reported. Bad input (another type on a topic, an image whose
// step or size disagrees with its data, no camera_info) is warned about,
// naming the topic, and never stops it.
#pragma once

#include <bims/pipeline/config.h>
#include <bims/pipeline/run.h>
#include <bims/ros2/params.h>

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace bims::ros2
{
struct NodeOptions
{
	std::string program = "bims-ros2";
	size_t maxFrames = 0;  ///< stop after N frames processed (0: never)
	/** Where to write what bims-run writes (pipeline::RunRecorder; the
	 * caller prepares the folder); empty: nothing. */
	std::string outDir;
	/** Files the caller writes into outDir afterwards (its manifest). */
	std::vector<std::string> laterFiles;
	/** When it turns true: stop, process the frames received, return. */
	const std::atomic<bool>* stop = nullptr;
	/** Warnings and the report's lines, worded (default: none; the
	 * library prints nothing, bims-ros2 writes them to stderr). */
	std::function<void(const std::string&)> log;
};

struct NodeStats
{
	size_t depthReceived = 0;   ///< depth images taken from DDS
	size_t framesQueued = 0;    ///< made into a frame and queued
	size_t framesDropped = 0;   ///< queued, dropped for a newer one
	size_t framesRejected = 0;  ///< unusable (bad image, no camera_info)
	size_t framesProcessed = 0;
	size_t imuReceived = 0;
	size_t messagesRejected = 0;  ///< samples that did not decode
	/** The run as bims-run reports it (its error: what stopped it). */
	pipeline::RunSummary run;
};

/** Runs until the stop flag or maxFrames; throws std::runtime_error when
 * DDS cannot be set up. */
NodeStats runNode(const pipeline::ExperimentConfig& cfg, const Ros2Params& p,
                  const NodeOptions& opt);

/** The report's line ("N frames processed, M dropped (...)"). */
std::string formatStats(const NodeStats& s);

}  // namespace bims::ros2
