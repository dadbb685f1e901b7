// Internal: the files bims-run writes, frame by frame, so that a run stopped
// early leaves valid partial outputs. The writing runs on a background
// thread ([output] writer_thread), in the order the frames were given.
#pragma once

#include <bims/io/output_paths.h>
#include <bims/io/rawlog.h>
#include <bims/pipeline/pipeline.h>
#include <bims/pipeline/run.h>

#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "worker.h"

namespace bims::pipeline
{
class OutputWriter
{
 public:
	/** \a laterFiles: listed in the manifest from the start
	 * (RunOptions::laterFiles). */
	OutputWriter(const std::string& dir, const OutputParams& p,
	             const std::vector<std::string>& laterFiles = {});
	/** Queues the frame's outputs: mask PNG, moving-voxel PLY, trajectory and
	 * CSV lines (flushed), and the scan into the labelled rawlog with the
	 * mask as its pixel labels (set on \a scan itself, so the images are not
	 * copied: the caller must not touch \a scan any more). \a flags: the
	 * frame's ego flags as written (r.ego.flags and those the run adds).
	 * Returns the time spent waiting for room in the queue [ms]. Throws the
	 * error of an earlier write that failed. */
	double writeFrame(const FrameResult& r,
	                  mrpt::obs::CObservation3DRangeScan::Ptr scan,
	                  uint32_t flags);
	/** Queues a non-scan observation (IMU) for the labelled rawlog. */
	double writeOther(mrpt::obs::CObservation::Ptr obs);
	/** Waits for the queued writes, closes the labelled rawlog, writes the
	 * static map; returns its voxel count. Throws the first write error
	 * (after closing what is open). */
	size_t close(Pipeline& pipe);
	/** metrics.json. */
	void writeMetrics(const Pipeline& pipe, const RunSummary& sum);
	/** DIR/REL for a file the run writes, listed in its manifest first. */
	std::string file(const std::string& rel) { return manifest_->file(rel); }
	/** Writing time of each frame [ms] (with the observations queued
	 * before it); complete after close(). */
	const std::vector<double>& frameMs() const { return frameMs_; }
	/** The same in CPU time of the writing thread [ms]. */
	const std::vector<double>& frameCpuMs() const { return frameCpuMs_; }

 private:
	void doWriteFrame(const FrameResult& r,
	                  mrpt::obs::CObservation3DRangeScan& scan);

	std::string dir_;
	OutputParams p_;
	std::unique_ptr<OutputManifest> manifest_;
	std::unique_ptr<AppendFile> traj_, csv_;
	std::unique_ptr<RawlogWriter> rawlog_;
	size_t staticVoxels_ = 0;
	// written by the worker thread, read after close()
	std::vector<double> frameMs_, frameCpuMs_;
	double otherMs_ = 0, otherCpuMs_ = 0;
	// last member: its thread stops before the rest is destroyed
	SerialWorker worker_;
};

/** Writes points as an ASCII PLY (x y z float). Throws naming the file. */
void writePointsPly(const std::string& path,
                    const std::vector<mrpt::math::TPoint3D>& pts);

}  // namespace bims::pipeline
