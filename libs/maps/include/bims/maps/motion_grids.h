// The three tiers run in the paper's order for one frame.
#pragma once

#include <bims/maps/CMotionGridBase.h>

#include <memory>

namespace bims::maps
{
/** Output of MotionGrids::processFrame. */
struct MotionFrameResult
{
	/** Moving-pixel masks (255 = moving) by tier-1 MAP and tier-2 MAP: the
	 * tiers' lastMovingMask() (not copied), valid until the next frame;
	 * empty (0 x 0) for a frame skipped for its pose. */
	const PixelMask& maskTier1() const { return mask1_ ? *mask1_ : kNoMask; }
	const PixelMask& maskTier2() const { return mask2_ ? *mask2_ : kNoMask; }
	/** Number of hit voxels and of those labelled moving by each tier. */
	size_t hitVoxels = 0, movingTier1 = 0, movingTier2 = 0;
	/** Readings used and skipped in this frame. */
	FrameStats stats;
	/** Wall time of the map updates (without building the cloud) [ms]. */
	double updateMs = 0;

 private:
	friend class MotionGrids;
	static const PixelMask kNoMask;
	const PixelMask *mask1_ = nullptr, *mask2_ = nullptr;
};

/** Owns the three tiers (tiers 1 and 2 linked to tier 0) and runs one frame:
 * (1) tier 1 reads O- for the hit voxels, (2) tier 0 folds in the frame,
 * (3) tier 2 combines the labels with tier 1's posterior, (4) MAP per voxel
 * gives the moving voxels and the masks. */
class MotionGrids
{
 public:
	explicit MotionGrids(const GridParams& p = {});

	/** One frame from a scan and the pose T_WS of its scan frame {S} in
	 * {W} (scan.sensorPose is NOT added). \a labels may be null (no flow:
	 * tier 2 = tier 1). */
	const MotionFrameResult& processFrame(
	    const mrpt::obs::CObservation3DRangeScan& scan,
	    const mrpt::poses::CPose3D& T_WS, const PixelLabels* labels);
	/** Same, for a FrameCloud built by the caller with the same voxel
	 * size (throws std::invalid_argument otherwise). */
	const MotionFrameResult& processFrame(const FrameCloud& frame,
	                                      const PixelLabels* labels);
	/** Same; \a flowOff: the frame has no flow tier at all (depth only, no
	 * labels): tier 1 decides what exclude_moving leaves out (tier 2,
	 * without labels, equals it). Without \a flowOff a frame without labels
	 * (the first one) excludes nothing. */
	const MotionFrameResult& processFrame(const FrameCloud& frame,
	                                      const PixelLabels* labels,
	                                      bool flowOff);

	/** Builds the FrameCloud of a scan (as processFrame(scan, ...) does)
	 * into lastFrame(), for processFrame(lastFrame(), labels) later: the
	 * build touches nothing else, so it may run on another thread while
	 * the caller prepares the labels. */
	const FrameCloud& buildFrame(const mrpt::obs::CObservation3DRangeScan& scan,
	                             const mrpt::poses::CPose3D& T_WS);
	/** Same from a depth image with the caller's camera model \a K and
	 * optical-frame pose \a T_WC (FrameCloudBuilder::build). */
	const FrameCloud& buildFrame(const DepthImage& depth,
	                             const sensors::PinholeCamera& K,
	                             const mrpt::poses::CPose3D& T_WC);
	/** processFrame() of the frame built last (buildFrame): its cells go
	 * to tiers 1 and 2 without a copy, and with setDeferDecay() its decay
	 * waits for applyPendingDecay(). */
	const MotionFrameResult& processBuiltFrame(const PixelLabels* labels,
	                                           bool flowOff);
	/** The FrameCloud of the last processFrame(scan, ...) / buildFrame.
	 * processFrame(lastFrame(), ...) equals processBuiltFrame(); the next
	 * buildFrame() builds into another buffer. */
	const FrameCloud& lastFrame() const { return *frame_; }
	const MotionFrameResult& lastResult() const { return result_; }

	/** Tier 0, with a decay left by setDeferDecay() applied first (so not
	 * while applyPendingDecay() may run on another thread). */
	std::shared_ptr<COccupancyBayesGrid> occupancy()
	{
		applyPendingDecay();
		return tier0_;
	}
	/** Tier 0 as it is: a query that changes nothing. Throws
	 * std::logic_error while a decay left by setDeferDecay() is pending
	 * (the map would lack the last frame's misses): applyPendingDecay(),
	 * or the non-const occupancy(), first. */
	std::shared_ptr<const COccupancyBayesGrid> occupancy() const;
	std::shared_ptr<CBackgroundSubtractionGrid> background() const
	{
		return tier1_;
	}
	/** Tier 2 (flow consistency). */
	std::shared_ptr<CFlowConsistencyGrid> flowConsistency() const
	{
		return tier2_;
	}
	const GridParams& params() const { return p_; }
	void clear();

	/** With \a on, processFrame(lastFrame(), ...) leaves tier 0's decay of
	 * the frame (decay = frustum or raycast: the misses of the cells it did
	 * not hit) for applyPendingDecay(). The result, the masks and tiers 1
	 * and 2 are final without it: only the next frame's O- needs it. The
	 * next processFrame() applies a decay still pending first, so results
	 * do not change. applyPendingDecay() touches tier 0 and reads the frame
	 * it decays (held until then, so buildFrame() builds into another
	 * buffer): it may run on another thread while the caller uses nothing
	 * of these grids but buildFrame(), e.g. during the next frame's
	 * egomotion. A frame not built by buildFrame() is decayed at once. */
	void setDeferDecay(bool on) { deferDecay_ = on; }
	bool decayPending() const { return tier0_->decayPending(); }
	void applyPendingDecay();

	/** Which tier's MAP decides "moving" for exclude_moving (1 or 2;
	 * default 2). */
	void setDecisionTier(int tier);
	int decisionTier() const { return decisionTier_; }

 private:
	GridParams p_;
	std::shared_ptr<COccupancyBayesGrid> tier0_;
	std::shared_ptr<CBackgroundSubtractionGrid> tier1_;
	std::shared_ptr<CFlowConsistencyGrid> tier2_;
	/** Builds the next frame into the spare buffer (\a build(frame)) and
	 * makes it lastFrame(). */
	template <class Build>
	const FrameCloud& buildInto(const Build& build);
	/** processFrame()'s update of the tiers: O- of the hit voxels (with its
	 * neighbourhood), the posteriors of tiers 1 and 2 (post1_, post2_),
	 * tier 0 folding the frame in (holding the voxels the decision calls
	 * moving when \a exclude). */
	void updateTiers(const FrameCloud& f, const PixelLabels& labels,
	                 bool exclude, bool flowOff);
	/** Which cells tier 0 holds under exclude_moving (into hold_). */
	void holdMoving(const FrameCloud& f, bool flowOff);
	/** The cells of \a f as tiers 1 and 2 keep them: lastFrame()'s shared,
	 * a caller's frame's copied once. */
	std::shared_ptr<std::vector<VoxelKey>> keptCells(const FrameCloud& f);
	FrameCloudBuilder builder_;
	// lastFrame() and the buffer the next frame is built into (tiers 1 and
	// 2 may still hold the cells of either: a held buffer is replaced).
	std::shared_ptr<FrameCloud> frame_ = std::make_shared<FrameCloud>(), spare_;
	MotionFrameResult result_;
	std::vector<float> prior_, post1_, post2_;
	std::vector<float> priorN_;
	std::vector<uint8_t> hold_;
	// The cells of a caller's frame as kept by tiers 1 and 2 (one copy for
	// both): two buffers, the one the maps no longer hold is refilled.
	std::shared_ptr<std::vector<VoxelKey>> cellsBuf_[2];
	int decisionTier_ = 2;
	bool deferDecay_ = false;
	// The frame whose decay is pending (kept alive for it).
	std::shared_ptr<const FrameCloud> decaying_;
};

}  // namespace bims::maps
