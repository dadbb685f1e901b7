// Common base of the three Bayesian voxel grids: parameters, frame counting,
// bad-input accounting and the parts of mrpt::maps::CMetricMap they share.
#pragma once

#include <bims/common/warnings.h>
#include <bims/maps/frame_cloud.h>
#include <bims/maps/grid_params.h>

#include <mrpt/img/TColor.h>
#include <mrpt/maps/CMetricMap.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace bims::maps
{
/** Abstract base (not creatable). Derived grids are created by name from an
 * .ini (see docs/maps.md) or constructed directly. */
class CBayesVoxelGridBase : public mrpt::maps::CMetricMap
{
	DEFINE_VIRTUAL_SERIALIZABLE(CBayesVoxelGridBase)

 public:
	/** \throws std::invalid_argument if \a p is inconsistent. */
	explicit CBayesVoxelGridBase(const GridParams& p = {});

	const GridParams& params() const { return params_; }
	/** Number of frames folded in since construction / clear(). */
	uint32_t frameCount() const { return frameCount_; }
	/** Timestamp of the last frame folded in (INVALID_TIMESTAMP if none). */
	mrpt::Clock::time_point lastTimestamp() const { return lastTimestamp_; }
	/** Readings skipped so far, by reason, and frames with a bad pose. */
	const FrameStats& totalStats() const { return totalStats_; }
	/** Number of frames skipped for a non-finite pose. */
	size_t badPoseFrames() const { return badPoseFrames_; }

	/** Voxel key of a point of {W} [m]. */
	VoxelKey keyOf(const mrpt::math::TPoint3D& p_W) const;
	/** Centre of a voxel in {W} [m]. */
	mrpt::math::TPoint3D centerOf(const VoxelKey& k) const;

	/** Builds the FrameCloud of a 3D range scan taken from \a robotPose
	 * (T_WS = robotPose + scan.sensorPose), accounting for bad input.
	 * Returns false (frame skipped) for a non-finite pose. */
	bool buildFrame(const mrpt::obs::CObservation3DRangeScan& scan,
	                const mrpt::poses::CPose3D& robotPose,
	                FrameCloud& out) const;
	/** buildFrame() of \a obs if it is a 3D range scan (CMetricMap's
	 * insertObservation: \a robotPose, none the origin). Returns false (no
	 * frame) for another observation or a non-finite pose. */
	bool buildFrameOf(
	    const mrpt::obs::CObservation& obs,
	    const std::optional<const mrpt::poses::CPose3D>& robotPose,
	    FrameCloud& out) const;

	/** Adds a frame's statistics to the totals; warns once per reason
	 * (warnings()). Called by the update functions. */
	void accountFrame(const FrameStats& s) const;
	/** Receives the warnings of accountFrame() (readings skipped, cells
	 * over the memory budget): the program's own (bims::programWarnings())
	 * unless set. */
	void setWarnings(WarningCallback cb) { warn_ = std::move(cb); }

	bool isEmpty() const override { return frameCount_ == 0; }

 protected:
	double internal_computeObservationLikelihood(
	    const mrpt::obs::CObservation& obs,
	    const mrpt::poses::CPose3D& takenFrom) const override;
	bool internal_canComputeObservationLikelihood(
	    const mrpt::obs::CObservation& obs) const override;

	/** Resets counters (called by derived internal_clear()). */
	void clearBase();
	void setParamsBase(const GridParams& p);
	/** Serialises params and counters, the parameters in the layout of
	 * \a version (readBase(); older ones only to test the readers). */
	void writeBase(mrpt::serialization::CArchive& out,
	               uint8_t version = 4) const;
	/** \a version: of the parameters' serialisation. 4: key = value rows
	 * of GridParams::describe() (the layout for every key to come); before
	 * it, a fixed binary layout: 0 without p_unknown, bg_neighbourhood,
	 * exclude_moving; 1 without exclude_by; 2 without raycast_margin; 3
	 * all of them then. */
	void readBase(mrpt::serialization::CArchive& in, uint8_t version);

	/** Appends cubes of side voxel_size at \a centers with \a color to the
	 * visualisation (an mrpt::opengl::COctoMapVoxels). */
	void addVoxelsTo(mrpt::opengl::CSetOfObjects& o,
	                 const std::vector<mrpt::math::TPoint3D>& centers,
	                 const mrpt::img::TColor& color,
	                 const std::string& name) const;

	GridParams params_;
	uint32_t frameCount_ = 0;
	mrpt::Clock::time_point lastTimestamp_{};
	mutable FrameStats totalStats_;
	mutable size_t badPoseFrames_ = 0;
	mutable FrameCloudBuilder builder_;
	mutable unsigned warned_ = 0;
	WarningCallback warn_ = programWarnings();

 private:
	static GridParams readParamRows(mrpt::serialization::CArchive& in);
	static GridParams readParamsBinary(mrpt::serialization::CArchive& in,
	                                   uint8_t version);
};

}  // namespace bims::maps
