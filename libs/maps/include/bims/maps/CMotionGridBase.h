// Common part of tiers 1 and 2: per-voxel posterior of independent motion
// I for the voxels hit in a frame, the moving-pixel mask of the last frame,
// and the tier-0 map the prior O- is read from.
#pragma once

#include <bims/maps/COccupancyBayesGrid.h>

#include <memory>

namespace bims::maps
{
/** Abstract base of CBackgroundSubtractionGrid and CFlowConsistencyGrid.
 *
 * Where O- comes from: a tier-1/2 map reads the previous occupancy from a
 * tier-0 map. By default it owns a private COccupancyBayesGrid with the
 * same parameters, which it updates itself after reading O- (so the map
 * works alone through insertObservation()). linkOccupancy() makes it read
 * a shared tier-0 map instead, which it then never modifies: the owner
 * inserts each frame into that map too, before or after this one (the
 * frame is recognised by its timestamp, see
 * COccupancyBayesGrid::priorLogOdds). MotionGrids does all of this. */
class CMotionGridBase : public CBayesVoxelGridBase
{
	DEFINE_VIRTUAL_SERIALIZABLE(CMotionGridBase)

 public:
	/** The serialisation version of tiers 1 and 2 (one number for both): 3
	 * changed the cells, 4 added raycast_margin, 5 writes the parameters
	 * as key = value rows, so that a new parameter needs no new version. */
	static constexpr uint8_t kSerializationVersion = 5;

	/** What a voxel keeps between frames: the MAP decision (posterior of
	 * I > 1/2) at its last hit; 0 for a voxel never hit. The posteriors
	 * themselves are recomputed every frame (the model has no per-voxel
	 * state for tiers 1 and 2) and kept for the last frame only
	 * (lastPosterior()). One byte: tiers 1 and 2 rewrite a cell for every
	 * voxel hit. */
	struct Cell
	{
		uint8_t moving = 0;
	};
	using Storage = SparseVoxelGrid<Cell, 3>;

	explicit CMotionGridBase(const GridParams& p = {});

	/** Reads O- from \a t0 (shared; never modified by this map) instead of
	 * a private tier-0 map. nullptr returns to a private map. Throws
	 * std::invalid_argument if the voxel sizes differ. */
	void linkOccupancy(std::shared_ptr<const COccupancyBayesGrid> t0);
	/** The tier-0 map O- is read from (linked or private). */
	const COccupancyBayesGrid& occupancySource() const;
	bool isLinked() const { return linked_ != nullptr; }

	/** Replaces the parameters (clears the map). */
	void setParams(const GridParams& p);

	/** Stores the posterior log-odds (one per frame.cells) of a frame as
	 * this map's frame frameCount()+1 and computes the mask. */
	void store(const FrameCloud& frame,
	           const std::vector<float>& posteriorLogOdds);
	/** store() without copying the frame's cells and posteriors (~2 MB per
	 * VGA frame at 2 cm): \a cells holds frame.cells (shared: MotionGrids
	 * gives tiers 1 and 2 one copy; a map never modifies a vector another
	 * owner holds), \a posteriorLogOdds is swapped in (it is left holding
	 * the previous frame's values). */
	void store(const FrameCloud& frame, std::vector<float>&& posteriorLogOdds,
	           std::shared_ptr<std::vector<VoxelKey>> cells);
	/** a.store(frame, postA, cells) then b.store(frame, postB, cells) in
	 * one sweep over the frame's cells and one over its readings (tiers 1
	 * and 2 in MotionGrids). Same results; \a a and \a b must differ. */
	static void storePair(CMotionGridBase& a, std::vector<float>&& postA,
	                      CMotionGridBase& b, std::vector<float>&& postB,
	                      const FrameCloud& frame,
	                      const std::shared_ptr<std::vector<VoxelKey>>& cells);

	/** Posterior log-odds of I of each of the last frame's cells. */
	const std::vector<float>& lastPosterior() const { return lastPost_; }
	/** Voxels of the last frame (same order as lastPosterior()). */
	const std::vector<VoxelKey>& lastCells() const { return *lastCells_; }
	/** Moving-pixel mask of the last frame (MAP: posterior > 1/2). Empty
	 * (0 x 0) for unorganised clouds. */
	const PixelMask& lastMovingMask() const { return lastMask_; }

	/** Posterior probability of I at the voxel containing \a p_W if that
	 * voxel was hit in the last frame (and stored: within the memory
	 * budget), else nullopt. A query, not for loops: O(voxels of the last
	 * frame) for a voxel stored before. */
	std::optional<double> probabilityAt(const mrpt::math::TPoint3D& p_W) const;
	/** Whether the voxel was labelled moving (MAP) at its last hit. */
	bool wasMovingAtLastHit(const VoxelKey& k) const;
	/** Centres [m, {W}] of the last frame's voxels labelled moving. */
	std::vector<mrpt::math::TPoint3D> movingCells() const;
	/** Calls \a f(key, posterior log-odds) for each of the last frame's
	 * voxels labelled moving (MAP: posterior > 1/2), in lastCells() order:
	 * the one rule of movingCells() and maps::movingVoxels(). */
	template <class F>
	void forEachMovingCell(F&& f) const
	{
		const auto& cells = *lastCells_;
		for (size_t i = 0; i < cells.size(); ++i)
			if (lastPost_[i] > 0) f(cells[i], lastPost_[i]);
	}

	const Storage& storage() const { return grid_; }
	size_t memoryBytes() const { return grid_.memoryBytes(); }

	std::string asString() const override;
	/** Writes <prefix>_moving.ply (the last frame's moving voxels). */
	void saveMetricMapRepresentationToFile(
	    const std::string& prefix) const override;

 protected:
	/** Posterior log-odds per frame.cell from O- (tier specific). */
	virtual void computePosterior(const FrameCloud& frame,
	                              const std::vector<float>& priorO,
	                              std::vector<float>& post) = 0;

	void internal_clear() override;
	bool internal_insertObservation(
	    const mrpt::obs::CObservation& obs,
	    const std::optional<const mrpt::poses::CPose3D>& robotPose =
	        std::nullopt) override;
	void writeMotion(mrpt::serialization::CArchive& out) const;
	void readMotion(mrpt::serialization::CArchive& in, uint8_t version);
	void visualize(mrpt::opengl::CSetOfObjects& o, const mrpt::img::TColor& c,
	               const std::string& name) const;

	Storage grid_;
	std::vector<float> lastPost_;
	// Shared with copies of this map and with MotionGrids; modified only
	// through ownCells().
	std::shared_ptr<std::vector<VoxelKey>> lastCells_ =
	    std::make_shared<std::vector<VoxelKey>>();
	/** lastCells_, first replaced by a vector of its own if shared. */
	std::vector<VoxelKey>& ownCells();
	PixelMask lastMask_;
	std::vector<uint8_t> movingBits_;  // storeCellsOf scratch
	/** The cell writes and the mask of store(). */
	void storeCells(const FrameCloud& frame, const std::vector<float>& post);
	/** storeCells() of N maps in one sweep (defined for N = 1, 2). */
	template <size_t N>
	static void storeCellsOf(CMotionGridBase* const (&maps)[N],
	                         const std::vector<float>* const (&posts)[N],
	                         const FrameCloud& frame);
	std::shared_ptr<const COccupancyBayesGrid> linked_;
	std::shared_ptr<COccupancyBayesGrid> private_;
	mrpt::Clock::time_point lastTimestampLocal_{};
};

/** Tier 1: background subtraction (paper eq. 4). P(I) recomputed every
 * frame from O- (not recursive); reported for hit voxels only.
 * .ini name: "backgroundSubtractionGrid". */
class CBackgroundSubtractionGrid : public CMotionGridBase
{
	DEFINE_SERIALIZABLE(CBackgroundSubtractionGrid, bims::maps)

 public:
	explicit CBackgroundSubtractionGrid(const GridParams& p = {});

	/** Tier-1 posterior log-odds for each of frame.cells from O-. */
	void posterior(const FrameCloud& frame, const std::vector<float>& priorO,
	               std::vector<float>& post) const
	{
		posterior(params_, frame, priorO, post);
	}
	/** The same with parameters \a p (no map needed: tier 2 on its own
	 * computes tier 1 through it). */
	static void posterior(const GridParams& p, const FrameCloud& frame,
	                      const std::vector<float>& priorO,
	                      std::vector<float>& post);

	void getVisualizationInto(mrpt::opengl::CSetOfObjects& o) const override;

	MAP_DEFINITION_START(CBackgroundSubtractionGrid)
	GridParams params;
	MAP_DEFINITION_END(CBackgroundSubtractionGrid)

 protected:
	void computePosterior(const FrameCloud& frame,
	                      const std::vector<float>& priorO,
	                      std::vector<float>& post) override
	{
		posterior(frame, priorO, post);
	}
};

/** Tier 2: optical-flow consistency (paper eq. 9). Combines tier 1's
 * posterior with the per-pixel Diff/notDiff labels of the frame.
 * Through insertObservation(), the labels are those given by
 * setPendingLabels() before the call (consumed by it; without labels, every
 * reading is unlabelled and tier 2 equals tier 1). .ini name:
 * "flowConsistencyGrid". */
class CFlowConsistencyGrid : public CMotionGridBase
{
	DEFINE_SERIALIZABLE(CFlowConsistencyGrid, bims::maps)

 public:
	explicit CFlowConsistencyGrid(const GridParams& p = {});

	/** Labels for the next insertObservation(). */
	void setPendingLabels(PixelLabels labels);

	/** Counts the Diff (k) and notDiff (l) readings of each frame cell.
	 * Throws std::invalid_argument if the label image size differs from
	 * the frame's. */
	static void countLabels(const FrameCloud& frame, const PixelLabels& labels,
	                        std::vector<uint32_t>& k, std::vector<uint32_t>& l);

	/** Tier-2 posterior log-odds for each of frame.cells from the tier-1
	 * posterior log-odds \a tier1 and the labels. */
	void posterior(const FrameCloud& frame, const PixelLabels& labels,
	               const std::vector<float>& tier1,
	               std::vector<float>& post) const;

	void getVisualizationInto(mrpt::opengl::CSetOfObjects& o) const override;

	MAP_DEFINITION_START(CFlowConsistencyGrid)
	GridParams params;
	MAP_DEFINITION_END(CFlowConsistencyGrid)

 protected:
	void computePosterior(const FrameCloud& frame,
	                      const std::vector<float>& priorO,
	                      std::vector<float>& post) override;

 private:
	PixelLabels pending_;
	std::vector<float> t1scratch_;
	// posterior(): the evidence of small label counts, for the parameters
	// it was tabulated with, and the per-cell counts (scratch).
	static constexpr uint32_t kTable = 32;
	struct DeltaTable
	{
		double tau = -1, pMiss = -1, logLambda = 0;
		bool veto = false;
		std::vector<double> d;  // kTable x kTable, [k][l]
	};
	mutable DeltaTable delta_;
	mutable std::vector<uint32_t> counts_;
};

}  // namespace bims::maps
