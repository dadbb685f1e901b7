// Reading a rawlog for replay: the frames of bims::source::RawlogFrameSource
// (the one ordering rule bims-run and every program share), restartable, with
// the frames' stamps known up front for the timeline.
#pragma once

#include <bims/source/frame_source.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace bims::viewer
{
/** Sequential, restartable frames of one rawlog. */
class ReplaySource
{
 public:
	/** Opens \a path and runs the rule over it once to index the frames
	 * (their stamps); throws RawlogError naming the file on a bad or
	 * truncated file, and std::runtime_error when it holds no 3D scan with
	 * the label. */
	ReplaySource(const std::string& path, source::FrameOrderParams p);

	/** Stamps of the frames the rule releases, in order [s]. */
	const std::vector<double>& frameTimes() const { return times_; }
	size_t frameCount() const { return times_.size(); }
	/** Number of IMU samples with the label in the file. */
	size_t imuCount() const { return nImu_; }
	const std::string& path() const { return path_; }

	/** The next frame, or nullopt at the end of the file. */
	std::optional<source::SourceFrame> next();
	/** Back to the start of the file. */
	void rewind();

 private:
	std::string path_;
	source::FrameOrderParams p_;
	std::vector<double> times_;
	size_t nImu_ = 0;
	std::unique_ptr<source::RawlogFrameSource> src_;
};

}  // namespace bims::viewer
