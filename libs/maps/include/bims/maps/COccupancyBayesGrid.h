// Tier 0: the Bayesian occupancy grid of the paper's eq. 3 (docs/model.md).
#pragma once

#include <bims/maps/CBayesVoxelGridBase.h>
#include <bims/maps/logodds_fixed.h>
#include <bims/maps/ray_marks.h>
#include <bims/maps/sparse_voxel_grid.h>

#include <mrpt/maps/TMetricMapInitializer.h>

#include <algorithm>
#include <optional>

namespace bims::maps
{
/** Tier 0 occupancy grid: log-odds of O per voxel, clamped to
 * [logit(p_min), logit(p_max)], each voxel updated once per frame (hits
 * win over misses), unobserved cells decaying by log(2 - p_miss) per frame
 * according to params().decay (lazily for decay = all).
 *
 * Use through the CMetricMap interface (insertObservation of a
 * CObservation3DRangeScan) or, sharing one FrameCloud with the other tiers,
 * through integrate(). .ini name: "occupancyBayesGrid" (docs/maps.md). */
class COccupancyBayesGrid : public CBayesVoxelGridBase
{
	DEFINE_SERIALIZABLE(COccupancyBayesGrid, bims::maps)

 public:
	/** Storage cell: fixed-point log-odds at frame `stamp`, and the value
	 * O- it had just before that frame's update. Never-touched cells are
	 * {0, 0, 0}: the prior 0.5 before frame 1. */
	struct Cell
	{
		LogOddsFx l = 0;
		LogOddsFx lPrev = 0;
		uint32_t stamp = 0;
	};
	using Storage = SparseVoxelGrid<Cell, 3>;

	explicit COccupancyBayesGrid(const GridParams& p = {});

	/** Replaces the parameters (clears the map if voxel_size or decay
	 * changes). */
	void setParams(const GridParams& p);

	/** Folds one frame in (frame number frameCount()+1). If
	 * \a priorLogOdds is given it receives O- (log-odds before this frame,
	 * after lazy decay) for each of frame.cells, for tier 1. If \a hold is
	 * given (one flag per frame cell), a cell with a non-zero flag keeps its
	 * belief: no hit, no miss and no free-space evidence in this frame, as
	 * for the readings of a moving object (GridParams::exclude_moving). */
	void integrate(const FrameCloud& frame,
	               std::vector<float>* priorLogOdds = nullptr,
	               const std::vector<uint8_t>* hold = nullptr);

	/** integrate() in two halves, for MotionGrids with exclude_moving, with
	 * one storage lookup per voxel for both: beginFrame() gives O- of each
	 * of frame.cells exactly as priorLogOdds() would (and creates the
	 * voxels' blocks, as integrate() would); integratePending(frame, hold)
	 * then equals integrate(frame, nullptr, hold). Nothing else may update
	 * this map in between (std::logic_error otherwise). */
	void beginFrame(const FrameCloud& frame, std::vector<float>& priorLogOdds);
	void integratePending(const FrameCloud& frame,
	                      const std::vector<uint8_t>* hold);

	/** Leaves the decay of each frame (decay = frustum or raycast: the
	 * misses of the cells the frame did not hit) for applyPendingDecay():
	 * integrate() and integratePending() then apply the hits only. The
	 * decay reads the frame, which must stay alive and unchanged until
	 * applyPendingDecay(); until then the map lacks the frame's misses, and
	 * integrate(), beginFrame() and integratePending() throw
	 * std::logic_error. With decay = all (lazy) nothing is left. */
	void setDeferDecay(bool on) { deferDecay_ = on; }
	/** A frame's decay is waiting for applyPendingDecay(). */
	bool decayPending() const { return decayOf_ != nullptr; }
	/** Applies the decay left by the last integrate()/integratePending()
	 * (nothing if none): the map is then as if integrate() had not
	 * deferred it. It touches this map and reads the frame only. */
	void applyPendingDecay();

	/** O- for each of frame.cells, without modifying the map. Order
	 * independent: if this frame (same non-zero timestamp) was already
	 * integrated, returns the values from before it.*/
	void priorLogOdds(const FrameCloud& frame, std::vector<float>& out) const;

	/** For each of frame.cells, the largest of \a prior (its O-) and the
	 * priors of the neighbours in \a n that tier 0 has observed, all before
	 * this frame is integrated: a reading next to a known surface is
	 * explained by it (GridParams::bg_neighbourhood). */
	void neighbourhoodMaxPrior(const FrameCloud& frame,
	                           const std::vector<float>& prior,
	                           BgNeighbourhood n,
	                           std::vector<float>& out) const;

	/** Current log-odds of the voxel containing \a p_W (after all decay up
	 * to frameCount()); the prior 0 decayed for never-touched space. */
	double logOddsAt(const mrpt::math::TPoint3D& p_W) const;
	/** Current occupancy probability of the voxel containing \a p_W. */
	double probabilityAt(const mrpt::math::TPoint3D& p_W) const;
	/** Current fixed-point log-odds of a voxel. */
	LogOddsFx logOddsFixed(const VoxelKey& k) const;
	/** Centres [m, {W}] of the stored voxels with probability > p. */
	std::vector<mrpt::math::TPoint3D> cellsAbove(double p) const;
	/** Keys of the stored voxels with probability > p. */
	std::vector<VoxelKey> keysAbove(double p) const;

	/** Quantised update constants (for tests and docs). */
	LogOddsFx missFixed() const { return miss_; }
	LogOddsFx minFixed() const { return lmin_; }
	LogOddsFx maxFixed() const { return lmax_; }
	LogOddsFx hitFixed(uint32_t n) const;

	const Storage& storage() const { return grid_; }
	size_t memoryBytes() const { return grid_.memoryBytes(); }

	void getVisualizationInto(mrpt::opengl::CSetOfObjects& o) const override;
	std::string asString() const override;
	/** Writes <prefix>_occupied.ply (voxels with p > 0.5). */
	void saveMetricMapRepresentationToFile(
	    const std::string& prefix) const override;

	MAP_DEFINITION_START(COccupancyBayesGrid)
	GridParams params;
	MAP_DEFINITION_END(COccupancyBayesGrid)

 protected:
	void internal_clear() override;
	bool internal_insertObservation(
	    const mrpt::obs::CObservation& obs,
	    const std::optional<const mrpt::poses::CPose3D>& robotPose =
	        std::nullopt) override;

 private:
	void updateConstants();
	/** The frame O- is read for: the frame being integrated, or the last
	 * one again if \a f repeats its timestamp (tier 1 reading O- of a frame
	 * tier 0 already holds). */
	uint32_t priorFrameOf(const FrameCloud& f) const;
	LogOddsFx hitFixedCompute(uint32_t n) const;
	LogOddsFx currentFixed(const Cell& c) const;
	void decayFrustum(const FrameCloud& f, uint32_t F);
	void decayRaycast(const FrameCloud& f, uint32_t F);
	/** The ends of decayRaycast()'s rays, into rayEnds_ (tile order). */
	void collectRayEnds(const FrameCloud& f, double inv);
	/** The rays through the voxel bitsets of \a box (ray_marks.h): each
	 * crossed voxel found once, then missed once. Returns the steps into
	 * blocks over the memory budget. */
	size_t castMarked(const double a[3], const RayBox& box, uint32_t F);
	/** The rays one voxel at a time through a cached-block accessor (boxes
	 * too large for the bitsets). Returns the steps over the budget. */
	size_t castPlain(const double a[3], uint32_t F);
	/** The missed cells of castMarked(), from the crossed bits of \a m;
	 * \a cells: those of each block of m.touched, nullptr if not stored. */
	void applyRayMarks(const RayMarks& m, Cell* const* cells, uint32_t F);
	/** One miss in frame F, unless the cell was hit or missed in it. */
	void applyMiss(Cell& c, uint32_t F) const
	{
		if (c.stamp == F) return;
		startIfUnobserved(c, c.stamp);
		c.lPrev = c.l;
		c.l = std::max<LogOddsFx>(c.l - miss_, lmin_);
		c.stamp = F;
	}
	/** The update of integrate(): of the cells in cellPtr_ if \a resolved
	 * (beginFrame() found them), else finding them on the way. */
	void applyFrame(const FrameCloud& f, std::vector<float>* priorOut,
	                const std::vector<uint8_t>* hold, bool resolved);
	void checkFrame(const FrameCloud& f, const char* what) const;

	// The cells of the frame being integrated (nullptr: over budget) and,
	// between beginFrame() and integratePending(), which frame they are.
	std::vector<Cell*> cellPtr_;
	const FrameCloud* pending_ = nullptr;
	uint32_t pendingFrame_ = 0;
	// setDeferDecay(): the frame whose decay waits, and its frame number.
	bool deferDecay_ = false;
	const FrameCloud* decayOf_ = nullptr;
	uint32_t decayFrame_ = 0;
	void throwIfDecayPending(const char* what) const;

	Storage grid_;
	// Scratch of decayRaycast(), reused across frames.
	std::vector<RayEnd> rayEnds_;
	std::vector<uint32_t> tileStart_;
	std::vector<Cell*> blockCells_;
	std::vector<RayMarks> rayMarks_;  // one per thread
	// Scratch of decayFrustum(): per-tile depth bounds.
	std::vector<float> tileMax_, tileMinPos_;
	std::vector<uint8_t> tileZero_;
	LogOddsFx miss_ = 0, lmin_ = 0, lmax_ = 0;
	/** p_unknown > 0: the log-odds of a never-observed cell. */
	bool hasUnknown_ = false;
	LogOddsFx unknown_ = 0;
	/** Prior (before frame G) of a cell, lazily decayed under decay = all;
	 * a never-observed cell has the unknown prior. */
	LogOddsFx priorFixed(const Cell& c, uint32_t G) const;
	/** A never-observed cell (\a stamp, its stamp before this update, is
	 * 0) starts from the unknown prior (p_unknown > 0) at its first miss. */
	void startIfUnobserved(Cell& c, uint32_t stamp) const
	{
		if (stamp == 0 && hasUnknown_) c.l = unknown_;
	}
	double logLambda_ = 0;
	std::vector<LogOddsFx> hitTable_;
};

}  // namespace bims::maps
