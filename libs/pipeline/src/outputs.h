// Internal: the files bims-run writes, frame by frame, so that a run stopped
// early leaves valid partial outputs.
#pragma once

#include <bims/common/rawlog.h>
#include <bims/pipeline/pipeline.h>
#include <bims/pipeline/run.h>

#include <fstream>
#include <memory>
#include <string>

namespace bims::pipeline
{
class OutputWriter
{
 public:
	OutputWriter(const std::string& dir, const OutputParams& p);
	/** Mask PNG, moving-voxel PLY, trajectory and CSV lines (flushed), and
	 * the scan into the labelled rawlog: the mask is attached to \a scan as
	 * its pixel labels (in place, so the images are not copied). */
	void writeFrame(const FrameResult& r,
	                mrpt::obs::CObservation3DRangeScan& scan);
	/** Passes a non-scan observation (IMU) into the labelled rawlog. */
	void writeOther(const mrpt::obs::CObservation& obs);
	/** Static map and metrics.json; returns the static map's voxel count. */
	size_t finish(const Pipeline& pipe, const RunSummary& sum);

 private:
	std::string dir_;
	OutputParams p_;
	std::ofstream traj_, csv_;
	std::unique_ptr<RawlogWriter> rawlog_;
};

/** Writes points as an ASCII PLY (x y z float). Throws naming the file. */
void writePointsPly(const std::string& path,
                    const std::vector<mrpt::math::TPoint3D>& pts);

}  // namespace bims::pipeline
