#include <bims/common/clock.h>
#include <bims/maps/motion_grids.h>

#include <chrono>
#include <stdexcept>

namespace bims::maps
{
const PixelMask MotionFrameResult::kNoMask;

MotionGrids::MotionGrids(const GridParams& p)
    : p_(p),
      tier0_(std::make_shared<COccupancyBayesGrid>(p)),
      tier1_(std::make_shared<CBackgroundSubtractionGrid>(p)),
      tier2_(std::make_shared<CFlowConsistencyGrid>(p)),
      builder_(p)
{
	tier1_->linkOccupancy(tier0_);
	tier2_->linkOccupancy(tier0_);
}

void MotionGrids::setDecisionTier(int tier)
{
	if (tier != 1 && tier != 2)
		throw std::invalid_argument(
		    "MotionGrids::setDecisionTier: tier must be 1 or 2");
	decisionTier_ = tier;
}

void MotionGrids::clear()
{
	decaying_.reset();
	tier0_->clear();
	tier1_->clear();
	tier2_->clear();
}

void MotionGrids::applyPendingDecay()
{
	tier0_->applyPendingDecay();
	decaying_.reset();
}

std::shared_ptr<const COccupancyBayesGrid> MotionGrids::occupancy() const
{
	if (tier0_->decayPending())
		throw std::logic_error(
		    "MotionGrids::occupancy() const: the last frame's tier-0 decay is "
		    "pending (applyPendingDecay() first)");
	return tier0_;
}

template <class Build>
const FrameCloud& MotionGrids::buildInto(const Build& build)
{
	if (!spare_ || spare_.use_count() != 1)
		spare_ = std::make_shared<FrameCloud>();
	build(*spare_);
	std::swap(frame_, spare_);
	return *frame_;
}

const FrameCloud& MotionGrids::buildFrame(
    const mrpt::obs::CObservation3DRangeScan& scan,
    const mrpt::poses::CPose3D& T_WS)
{
	return buildInto([&](FrameCloud& f) { builder_.build(scan, T_WS, f); });
}

const FrameCloud& MotionGrids::buildFrame(const DepthImage& depth,
                                          const sensors::PinholeCamera& K,
                                          const mrpt::poses::CPose3D& T_WC)
{
	return buildInto([&](FrameCloud& f) { builder_.build(depth, K, T_WC, f); });
}

const MotionFrameResult& MotionGrids::processBuiltFrame(
    const PixelLabels* labels, bool flowOff)
{
	return processFrame(*frame_, labels, flowOff);
}

const MotionFrameResult& MotionGrids::processFrame(
    const mrpt::obs::CObservation3DRangeScan& scan,
    const mrpt::poses::CPose3D& T_WS, const PixelLabels* labels)
{
	return processFrame(buildFrame(scan, T_WS), labels);
}

const MotionFrameResult& MotionGrids::processFrame(const FrameCloud& f,
                                                   const PixelLabels* labels)
{
	return processFrame(f, labels, false);
}

void MotionGrids::holdMoving(const FrameCloud& f, bool flowOff)
{
	const auto& dec = decisionTier_ == 1 || flowOff ? post1_ : post2_;
	const bool either =
	    p_.exclude_by == ExcludeBy::Either ||
	    (p_.exclude_by == ExcludeBy::Auto && p_.decay != DecayMode::Raycast);
	hold_.resize(f.cells.size());
	for (size_t i = 0; i < f.cells.size(); ++i)
		hold_[i] = dec[i] > 0 || (either && post1_[i] > 0);
}

void MotionGrids::updateTiers(const FrameCloud& f, const PixelLabels& labels,
                              bool exclude, bool flowOff)
{
	const bool neighbours = p_.bg_neighbourhood != BgNeighbourhood::None;
	if (!exclude && !neighbours)
	{
		// (1)+(2): tier 0 hands out O- of the hit voxels, then folds the
		// frame in.
		tier0_->integrate(f, &prior_);
		// (3) tier 1 from O-, tier 2 from tier 1 and the flow labels.
		tier1_->posterior(f, prior_, post1_);
		tier2_->posterior(f, labels, post1_, post2_);
		return;
	}
	// O- first (with its neighbourhood), both posteriors, then tier 0 folds
	// the frame in: with exclude_moving only the voxels the decision tier
	// calls static (the moving ones keep their belief).
	tier0_->beginFrame(f, prior_);
	const std::vector<float>* o = &prior_;
	if (neighbours)
	{
		tier0_->neighbourhoodMaxPrior(f, prior_, p_.bg_neighbourhood, priorN_);
		o = &priorN_;
	}
	tier1_->posterior(f, *o, post1_);
	tier2_->posterior(f, labels, post1_, post2_);
	if (exclude)
	{
		holdMoving(f, flowOff);
		tier0_->integratePending(f, &hold_);
	}
	else
		tier0_->integratePending(f, nullptr);
}

std::shared_ptr<std::vector<VoxelKey>> MotionGrids::keptCells(
    const FrameCloud& f)
{
	if (&f == frame_.get())
		return std::shared_ptr<std::vector<VoxelKey>>(frame_, &frame_->cells);
	auto& buf = cellsBuf_[0].use_count() <= 1 ? cellsBuf_[0] : cellsBuf_[1];
	if (buf.use_count() != 1) buf = std::make_shared<std::vector<VoxelKey>>();
	*buf = f.cells;
	return buf;
}

const MotionFrameResult& MotionGrids::processFrame(const FrameCloud& f,
                                                   const PixelLabels* labels,
                                                   bool flowOff)
{
	if (f.voxel_size != p_.voxel_size)
		throw std::invalid_argument(
		    "MotionGrids::processFrame: frame keyed for another voxel size");
	applyPendingDecay();  // the last frame's, if the caller has not
	tier0_->setDeferDecay(deferDecay_ && &f == frame_.get());
	result_ = MotionFrameResult();
	result_.stats = f.stats;
	tier0_->accountFrame(f.stats);
	if (f.stats.badPose) return result_;
	const auto t0 = std::chrono::steady_clock::now();
	static const PixelLabels none;
	// Without flow labels (first frame) there is no decision to exclude by;
	// without a flow tier (flowOff) tier 1's is the decision (tier 2
	// equals it without labels).
	const bool exclude = p_.exclude_moving && (labels || flowOff);
	updateTiers(f, labels ? *labels : none, exclude, flowOff);
	// (4) MAP per voxel; masks.
	result_.hitVoxels = f.cells.size();
	for (size_t i = 0; i < f.cells.size(); ++i)
	{
		result_.movingTier1 += post1_[i] > 0;
		result_.movingTier2 += post2_[i] > 0;
	}
	// Tiers 1 and 2 keep the cells of lastFrame() (shared, no copy) or one
	// copy of a caller's frame's, and the posteriors without a copy (post1_,
	// post2_ are recomputed every frame). One sweep over the cells and
	// readings stores both tiers.
	CMotionGridBase::storePair(*tier1_, std::move(post1_), *tier2_,
	                           std::move(post2_), f, keptCells(f));
	result_.mask1_ = &tier1_->lastMovingMask();
	result_.mask2_ = &tier2_->lastMovingMask();
	result_.updateMs = msSince(t0);
	if (tier0_->decayPending()) decaying_ = frame_;
	return result_;
}

}  // namespace bims::maps
