// Tier 0: integration of a frame (hits, lazy decay) and queries.
#include <bims/maps/COccupancyBayesGrid.h>
#include <bims/maps/closed_form.h>

#include "internal.h"

#include <mrpt/obs/CObservation3DRangeScan.h>

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

LogOddsFx COccupancyBayesGrid::currentFixed(const Cell& c) const
{
	if (params_.decay != DecayMode::All) return c.l;
	return decayFixed(c.l, frameCount_ - c.stamp, miss_, lmin_);
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

void COccupancyBayesGrid::applyMiss(Cell& c, uint32_t F) const
{
	if (c.stamp == F) return;  // hit (or already missed) in this frame
	c.lPrev = c.l;
	c.l = std::max<LogOddsFx>(c.l - miss_, lmin_);
	c.stamp = F;
}

void COccupancyBayesGrid::integrate(const FrameCloud& f,
                                    std::vector<float>* priorOut)
{
	if (f.voxel_size != params_.voxel_size)
		throw std::invalid_argument(
		    "COccupancyBayesGrid::integrate: frame keyed for voxel size " +
		    std::to_string(f.voxel_size) + " m, grid has " +
		    std::to_string(params_.voxel_size) + " m");
	const uint32_t F = frameCount_ + 1;
	const bool lazy = params_.decay == DecayMode::All;
	if (priorOut) priorOut->resize(f.cells.size());
	FrameStats st;
	Storage::Accessor acc(grid_);
	const size_t m = f.cells.size();
	for (size_t i = 0; i < m; ++i)
	{
		if (i + kPrefetchAhead < m)
		{
			const VoxelKey& q = f.cells[i + kPrefetchAhead];
			acc.prefetch(q.x, q.y, q.z);
		}
		const VoxelKey& k = f.cells[i];
		Cell* c = acc.get(k.x, k.y, k.z);
		if (!c)
		{
			st.overBudget += f.hits[i];
			if (priorOut)
				(*priorOut)[i] = float(
				    fromFixed(lazy ? decayFixed(0, F - 1, miss_, lmin_) : 0));
			continue;
		}
		const LogOddsFx prior =
		    lazy ? decayFixed(c->l, F - 1 - c->stamp, miss_, lmin_) : c->l;
		c->lPrev = prior;
		c->l = LogOddsFx(
		    std::min<int64_t>(int64_t(prior) + hitFixed(f.hits[i]), lmax_));
		c->stamp = F;
		if (priorOut) (*priorOut)[i] = float(fromFixed(prior));
	}
	if (params_.decay == DecayMode::Raycast) decayRaycast(f, F);
	if (params_.decay == DecayMode::Frustum) decayFrustum(f, F);
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
	const bool lazy = params_.decay == DecayMode::All;
	const bool already = frameCount_ > 0 &&
	                     f.timestamp != mrpt::Clock::time_point() &&
	                     f.timestamp == lastTimestamp_;
	const uint32_t G = already ? frameCount_ : frameCount_ + 1;
	out.resize(f.cells.size());
	for (size_t i = 0; i < f.cells.size(); ++i)
	{
		const Cell* c = grid_.find(f.cells[i]);
		const Cell cell = c ? *c : Cell();
		LogOddsFx v;
		if (already && cell.stamp == G)
			v = cell.lPrev;
		else
			v = lazy ? decayFixed(cell.l, G - 1 - cell.stamp, miss_, lmin_)
			         : cell.l;
		out[i] = float(fromFixed(v));
	}
}

bool COccupancyBayesGrid::internal_insertObservation(
    const mrpt::obs::CObservation& obs,
    const std::optional<const mrpt::poses::CPose3D>& robotPose)
{
	const auto* scan =
	    dynamic_cast<const mrpt::obs::CObservation3DRangeScan*>(&obs);
	if (!scan) return false;
	FrameCloud f;
	if (!buildFrame(*scan, robotPose ? *robotPose : mrpt::poses::CPose3D(), f))
		return false;
	integrate(f);
	return true;
}

void COccupancyBayesGrid::internal_clear()
{
	grid_.clear();
	clearBase();
}

}  // namespace bims::maps
