// Tier 0: integration of a frame (hits, lazy decay) and queries.
#include <bims/maps/COccupancyBayesGrid.h>
#include <bims/maps/closed_form.h>

#include "internal.h"

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace bims::maps
{
COccupancyBayesGrid::COccupancyBayesGrid(const GridParams& p)
    : CBayesVoxelGridBase(p)
{
	grid_.setMaxBytes(size_t(p.max_memory_mb * 1048576.0));
	updateConstants();
}

void COccupancyBayesGrid::setParams(const GridParams& p)
{
	// Stored stamps mean "lazily decayed" only under decay = all: a change of
	// voxel size or of decay mode invalidates the content.
	const bool sizeChanged =
	    p.voxel_size != params_.voxel_size || p.decay != params_.decay;
	setParamsBase(p);
	grid_.setMaxBytes(size_t(p.max_memory_mb * 1048576.0));
	updateConstants();
	if (sizeChanged) clear();
}

void COccupancyBayesGrid::updateConstants()
{
	const auto& p = params_;
	miss_ = toFixed(-missLogOdds(p.p_miss));
	lmin_ = toFixed(logit(p.p_min));
	lmax_ = toFixed(logit(p.p_max));
	logLambda_ = std::log(p.reading_lambda);
	hasUnknown_ = p.p_unknown > 0;
	unknown_ =
	    hasUnknown_ ? std::clamp(toFixed(logit(p.p_unknown)), lmin_, lmax_) : 0;
	hitTable_.clear();
	for (uint32_t n = 0; n <= 1024; ++n)
		hitTable_.push_back(hitFixedCompute(n));
}

LogOddsFx COccupancyBayesGrid::hitFixed(uint32_t n) const
{
	return n < hitTable_.size() ? hitTable_[n] : hitFixedCompute(n);
}

LogOddsFx COccupancyBayesGrid::hitFixedCompute(uint32_t n) const
{
	if (n == 0) return 0;
	// Increments beyond the clamping range are equivalent after clamping.
	const double range = fromFixed(lmax_) - fromFixed(lmin_) + 1;
	return toFixed(std::min(hitLogOdds(params_.p_miss, logLambda_, n), range));
}

LogOddsFx COccupancyBayesGrid::priorFixed(const Cell& c, uint32_t G) const
{
	if (c.stamp == 0 && hasUnknown_) return unknown_;
	if (params_.decay != DecayMode::All) return c.l;
	return decayFixed(c.l, G - 1 - c.stamp, miss_, lmin_);
}

LogOddsFx COccupancyBayesGrid::currentFixed(const Cell& c) const
{
	return priorFixed(c, frameCount_ + 1);
}

LogOddsFx COccupancyBayesGrid::logOddsFixed(const VoxelKey& k) const
{
	const Cell* c = grid_.find(k);
	return currentFixed(c ? *c : Cell());
}

double COccupancyBayesGrid::logOddsAt(const mrpt::math::TPoint3D& p) const
{
	return fromFixed(logOddsFixed(keyOf(p)));
}

double COccupancyBayesGrid::probabilityAt(const mrpt::math::TPoint3D& p) const
{
	return sigmoid(logOddsAt(p));
}

std::vector<VoxelKey> COccupancyBayesGrid::keysAbove(double p) const
{
	const LogOddsFx th = toFixed(logit(p));
	std::vector<VoxelKey> out;
	for (size_t b = 0; b < grid_.numBlocks(); ++b)
	{
		const auto& blk = grid_.block(b);
		for (size_t c = 0; c < Storage::kCellsPerBlock; ++c)
			if (blk.cells[c].stamp != 0 && currentFixed(blk.cells[c]) > th)
				out.push_back(grid_.cellKey(b, c));
	}
	return out;
}

std::vector<mrpt::math::TPoint3D> COccupancyBayesGrid::cellsAbove(
    double p) const
{
	std::vector<mrpt::math::TPoint3D> out;
	for (const auto& k : keysAbove(p)) out.push_back(centerOf(k));
	return out;
}

void COccupancyBayesGrid::checkFrame(const FrameCloud& f,
                                     const char* what) const
{
	if (f.voxel_size != params_.voxel_size)
		throw std::invalid_argument(
		    std::string("COccupancyBayesGrid::") + what +
		    ": frame keyed for voxel size " + std::to_string(f.voxel_size) +
		    " m, grid has " + std::to_string(params_.voxel_size) + " m");
}

void COccupancyBayesGrid::throwIfDecayPending(const char* what) const
{
	if (decayOf_)
		throw std::logic_error(std::string("COccupancyBayesGrid::") + what +
		                       ": the decay of frame " +
		                       std::to_string(decayFrame_) +
		                       " is still pending (applyPendingDecay() first)");
}

void COccupancyBayesGrid::applyPendingDecay()
{
	if (!decayOf_) return;
	const FrameCloud& f = *decayOf_;
	decayOf_ = nullptr;
	if (params_.decay == DecayMode::Raycast) decayRaycast(f, decayFrame_);
	if (params_.decay == DecayMode::Frustum) decayFrustum(f, decayFrame_);
}

void COccupancyBayesGrid::integrate(const FrameCloud& f,
                                    std::vector<float>* priorOut,
                                    const std::vector<uint8_t>* hold)
{
	if (hold && hold->size() != f.cells.size())
		throw std::invalid_argument(
		    "COccupancyBayesGrid::integrate: one hold flag per cell expected");
	checkFrame(f, "integrate");
	throwIfDecayPending("integrate");
	pending_ = nullptr;
	// The cells are found while the update runs (no array of pointers).
	cellPtr_.clear();
	applyFrame(f, priorOut, hold, false);
}

uint32_t COccupancyBayesGrid::priorFrameOf(const FrameCloud& f) const
{
	const bool already = frameCount_ > 0 &&
	                     f.timestamp != mrpt::Clock::time_point() &&
	                     f.timestamp == lastTimestamp_;
	return already ? frameCount_ : frameCount_ + 1;
}

void COccupancyBayesGrid::beginFrame(const FrameCloud& f,
                                     std::vector<float>& out)
{
	checkFrame(f, "beginFrame");
	throwIfDecayPending("beginFrame");
	grid_.resolve(f.cells, cellPtr_);
	pending_ = &f;
	pendingFrame_ = frameCount_;
	const uint32_t G = priorFrameOf(f);  // as priorLogOdds()
	const bool already = G == frameCount_;
	out.resize(f.cells.size());
	for (size_t i = 0; i < f.cells.size(); ++i)
	{
		const Cell cell = cellPtr_[i] ? *cellPtr_[i] : Cell();
		const LogOddsFx v =
		    (already && cell.stamp == G) ? cell.lPrev : priorFixed(cell, G);
		out[i] = float(fromFixed(v));
	}
}

void COccupancyBayesGrid::integratePending(const FrameCloud& f,
                                           const std::vector<uint8_t>* hold)
{
	throwIfDecayPending("integratePending");
	if (pending_ != &f || pendingFrame_ != frameCount_ ||
	    cellPtr_.size() != f.cells.size())
		throw std::logic_error(
		    "COccupancyBayesGrid::integratePending: not the frame of the last "
		    "beginFrame(), or the map changed in between");
	if (hold && hold->size() != f.cells.size())
		throw std::invalid_argument(
		    "COccupancyBayesGrid::integratePending: one hold flag per cell "
		    "expected");
	pending_ = nullptr;
	applyFrame(f, nullptr, hold, true);
}

namespace
{
// applyFrame()'s loop over the cells found by beginFrame(): update(i, c)
// of each (c prefetched kPrefetchAhead cells ahead).
template <class Cell, class Update>
void updateResolvedCells(Cell* const* cells, size_t m, Update& update)
{
	for (size_t i = 0; i < m; ++i)
	{
#if defined(__GNUC__)
		if (i + kPrefetchAhead < m && cells[i + kPrefetchAhead])
			__builtin_prefetch(cells[i + kPrefetchAhead], 1);
#endif
		update(i, cells[i]);
	}
}

// applyFrame()'s loop finding the cells on the way: found kPrefetchAhead
// cells ahead of the update (one index lookup per block, blocks created in
// the order of the cells as by Storage::resolve()) and prefetched.
template <class Cell, class Storage, class Update>
void updateFindingCells(Storage& grid, const VoxelKey* keys, size_t m,
                        Update& update)
{
	constexpr size_t kRing = 2 * kPrefetchAhead;
	static_assert((kRing & (kRing - 1)) == 0, "ring size: a power of two");
	Cell* ring[kRing];
	uint64_t lastKey = FlatHashMap::kEmpty;
	typename Storage::Block* last = nullptr;
	for (size_t i = 0; i < m + kPrefetchAhead; ++i)
	{
		if (i < m)
		{
			const VoxelKey& k = keys[i];
			const uint64_t bk = Storage::blockKeyOf(k.x, k.y, k.z);
			if (bk != lastKey)
			{
				const uint32_t b = grid.findOrCreateBlock(bk);
				last = b == FlatHashMap::kNotFound ? nullptr : &grid.block(b);
				lastKey = bk;
			}
			Cell* c = last ? &last->cells[Storage::cellIndexOf(k.x, k.y, k.z)]
			               : nullptr;
#if defined(__GNUC__)
			if (c) __builtin_prefetch(c, 1);
#endif
			ring[i % kRing] = c;
		}
		if (i >= kPrefetchAhead)
			update(i - kPrefetchAhead, ring[(i - kPrefetchAhead) % kRing]);
	}
}

// The cells of neighbouring voxels: mostly in the block of the cell or of
// the previous neighbour, so the last two blocks looked up are kept.
template <class Cell, class Storage>
struct NeighbourCells
{
	const Storage& grid;
	uint64_t lastKey[2] = {FlatHashMap::kEmpty, FlatHashMap::kEmpty};
	const typename Storage::Block* lastBlk[2] = {nullptr, nullptr};
	unsigned next = 0;

	const Cell* find(const VoxelKey& n)
	{
		const uint64_t bk = Storage::blockKeyOf(n.x, n.y, n.z);
		const typename Storage::Block* b;
		if (bk == lastKey[0])
			b = lastBlk[0];
		else if (bk == lastKey[1])
			b = lastBlk[1];
		else
		{
			b = grid.findBlock(bk);
			lastKey[next] = bk;
			lastBlk[next] = b;
			next ^= 1;
		}
		return b ? &b->cells[Storage::cellIndexOf(n.x, n.y, n.z)] : nullptr;
	}
};

// The voxels one edge in front of and behind the centre of \a k (side \a s),
// along the sensor ray from \a o (where depth noise moves a reading):
// consider(key) of each that is not \a k; keyOf(point) gives a key.
template <class KeyOf, class Consider>
void forRayNeighbours(const VoxelKey& k, double s,
                      const mrpt::math::TPoint3D& o, const KeyOf& keyOf,
                      Consider& consider)
{
	const double cx = (k.x + 0.5) * s, cy = (k.y + 0.5) * s,
	             cz = (k.z + 0.5) * s;
	double dx = cx - o.x, dy = cy - o.y, dz = cz - o.z;
	const double n = std::sqrt(dx * dx + dy * dy + dz * dz);
	if (!(n > 0)) return;
	dx *= s / n, dy *= s / n, dz *= s / n;
	for (int sg : {-1, 1})
	{
		const VoxelKey nk = keyOf({cx + sg * dx, cy + sg * dy, cz + sg * dz});
		if (!(nk == k)) consider(nk);
	}
}

// The 6 (faces only) or 26 voxels around \a k: consider(key) of each.
template <class Consider>
void forGridNeighbours(const VoxelKey& k, bool facesOnly, Consider& consider)
{
	for (int dz = -1; dz <= 1; ++dz)
		for (int dy = -1; dy <= 1; ++dy)
			for (int dx = -1; dx <= 1; ++dx)
			{
				const int m = std::abs(dx) + std::abs(dy) + std::abs(dz);
				if (m == 0 || (facesOnly && m > 1)) continue;
				consider({k.x + dx, k.y + dy, k.z + dz});
			}
}
}  // namespace

void COccupancyBayesGrid::applyFrame(const FrameCloud& f,
                                     std::vector<float>* priorOut,
                                     const std::vector<uint8_t>* hold,
                                     bool resolved)
{
	const uint32_t F = frameCount_ + 1;
	if (priorOut) priorOut->resize(f.cells.size());
	FrameStats st;
	const size_t m = f.cells.size();
	// priorFixed() and hitFixed() with the constants in locals: the cell
	// writes (int32 fields) could alias the members for the compiler.
	const bool lazy = params_.decay == DecayMode::All;
	const bool hasUnknown = hasUnknown_;
	const LogOddsFx unknown = unknown_, miss = miss_, lmin = lmin_,
	                lmax = lmax_;
	const LogOddsFx* hitTab = hitTable_.data();
	const uint32_t nTab = uint32_t(hitTable_.size());
	const uint32_t* hits = f.hits.data();
	const uint8_t* held = hold ? hold->data() : nullptr;
	float* pOut = priorOut ? priorOut->data() : nullptr;
	// The update of cell i (c: its storage, nullptr over budget).
	auto update = [&](size_t i, Cell* c)
	{
		if (!c)
		{
			st.overBudget += hits[i];
			if (pOut) pOut[i] = float(fromFixed(priorFixed(Cell(), F)));
			return;
		}
		const Cell old = *c;
		const LogOddsFx prior =
		    (old.stamp == 0 && hasUnknown)
		        ? unknown
		        : (lazy ? decayFixed(old.l, F - 1 - old.stamp, miss, lmin)
		                : old.l);
		const uint32_t n = hits[i];
		const LogOddsFx hit =
		    (held && held[i]) ? 0 : (n < nTab ? hitTab[n] : hitFixedCompute(n));
		*c = {LogOddsFx(std::min<int64_t>(int64_t(prior) + hit, lmax)), prior,
		      F};
		if (pOut) pOut[i] = float(fromFixed(prior));
	};
	if (resolved)
		updateResolvedCells(cellPtr_.data(), m, update);
	else
		updateFindingCells<Cell>(grid_, f.cells.data(), m, update);
	// The decay last (hits win), now or by applyPendingDecay().
	if (params_.decay != DecayMode::All)
	{
		decayOf_ = &f;
		decayFrame_ = F;
		if (!deferDecay_) applyPendingDecay();
	}
	frameCount_ = F;
	lastTimestamp_ = f.timestamp;
	if (st.overBudget) accountFrame(st);
}

void COccupancyBayesGrid::priorLogOdds(const FrameCloud& f,
                                       std::vector<float>& out) const
{
	if (f.voxel_size != params_.voxel_size)
		throw std::invalid_argument(
		    "COccupancyBayesGrid::priorLogOdds: voxel size mismatch");
	const uint32_t G = priorFrameOf(f);
	const bool already = G == frameCount_;
	out.resize(f.cells.size());
	for (size_t i = 0; i < f.cells.size(); ++i)
	{
		const Cell* c = grid_.find(f.cells[i]);
		const Cell cell = c ? *c : Cell();
		LogOddsFx v;
		if (already && cell.stamp == G)
			v = cell.lPrev;
		else
			v = priorFixed(cell, G);
		out[i] = float(fromFixed(v));
	}
}

void COccupancyBayesGrid::neighbourhoodMaxPrior(const FrameCloud& f,
                                                const std::vector<float>& prior,
                                                BgNeighbourhood nb,
                                                std::vector<float>& out) const
{
	if (prior.size() != f.cells.size())
		throw std::invalid_argument(
		    "COccupancyBayesGrid::neighbourhoodMaxPrior: one prior per cell "
		    "expected");
	if (nb == BgNeighbourhood::None)
	{
		out = prior;
		return;
	}
	out.resize(prior.size());
	const uint32_t G = frameCount_ + 1;
	const double s = params_.voxel_size;
	const auto& o = f.origin_W;
	NeighbourCells<Cell, Storage> cells{grid_};
	const auto keyOfPoint = [this](const mrpt::math::TPoint3D& p)
	{ return keyOf(p); };
	for (size_t i = 0; i < f.cells.size(); ++i)
	{
		out[i] = prior[i];
		const VoxelKey& k = f.cells[i];
		LogOddsFx best = std::numeric_limits<LogOddsFx>::min();
		auto consider = [&](const VoxelKey& n)
		{
			const Cell* c = cells.find(n);
			if (c && c->stamp != 0) best = std::max(best, priorFixed(*c, G));
		};
		if (nb == BgNeighbourhood::Ray)
			forRayNeighbours(k, s, o, keyOfPoint, consider);
		else
			forGridNeighbours(k, nb == BgNeighbourhood::Faces, consider);
		if (best != std::numeric_limits<LogOddsFx>::min())
			out[i] = std::max(out[i], float(fromFixed(best)));
	}
}

bool COccupancyBayesGrid::internal_insertObservation(
    const mrpt::obs::CObservation& obs,
    const std::optional<const mrpt::poses::CPose3D>& robotPose)
{
	FrameCloud f;
	if (!buildFrameOf(obs, robotPose, f)) return false;
	integrate(f);
	return true;
}

void COccupancyBayesGrid::internal_clear()
{
	decayOf_ = nullptr;  // a pending decay has no map left to act on
	grid_.clear();
	clearBase();
}

}  // namespace bims::maps
