// Tiers 1 and 2: shared storage of posteriors, masks and the O- source.
#include <bims/maps/CMotionGridBase.h>
#include <bims/maps/closed_form.h>
#include <bims/maps/export.h>

#include "internal.h"

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace bims::maps
{
IMPLEMENTS_VIRTUAL_SERIALIZABLE(CMotionGridBase, CBayesVoxelGridBase,
                                bims::maps)

CMotionGridBase::CMotionGridBase(const GridParams& p) : CBayesVoxelGridBase(p)
{
	grid_.setMaxBytes(size_t(p.max_memory_mb * 1048576.0));
}

void CMotionGridBase::setParams(const GridParams& p)
{
	setParamsBase(p);
	grid_.setMaxBytes(size_t(p.max_memory_mb * 1048576.0));
	if (private_) private_->setParams(p);
	clear();
}

void CMotionGridBase::linkOccupancy(
    std::shared_ptr<const COccupancyBayesGrid> t0)
{
	if (t0 && t0->params().voxel_size != params_.voxel_size)
		throw std::invalid_argument(std::string(GetRuntimeClass()->className) +
		                            "::linkOccupancy: tier-0 voxel size " +
		                            std::to_string(t0->params().voxel_size) +
		                            " m differs from " +
		                            std::to_string(params_.voxel_size) + " m");
	linked_ = std::move(t0);
}

const COccupancyBayesGrid& CMotionGridBase::occupancySource() const
{
	if (linked_) return *linked_;
	if (!private_)
		const_cast<CMotionGridBase*>(this)->private_ =
		    std::make_shared<COccupancyBayesGrid>(params_);
	return *private_;
}

std::vector<VoxelKey>& CMotionGridBase::ownCells()
{
	if (lastCells_.use_count() != 1)
		lastCells_ = std::make_shared<std::vector<VoxelKey>>();
	return *lastCells_;
}

void CMotionGridBase::store(const FrameCloud& f, const std::vector<float>& post)
{
	storeCells(f, post);
	ownCells() = f.cells;
	lastPost_ = post;
}

void CMotionGridBase::store(const FrameCloud& f, std::vector<float>&& post,
                            std::shared_ptr<std::vector<VoxelKey>> cells)
{
	if (!cells || cells->size() != f.cells.size())
		throw std::invalid_argument(
		    "CMotionGridBase::store: the shared cells are not the frame's");
	storeCells(f, post);
	lastCells_ = std::move(cells);
	lastPost_.swap(post);
}

void CMotionGridBase::storePair(
    CMotionGridBase& a, std::vector<float>&& postA, CMotionGridBase& b,
    std::vector<float>&& postB, const FrameCloud& f,
    const std::shared_ptr<std::vector<VoxelKey>>& cells)
{
	if (&a == &b)
		throw std::invalid_argument(
		    "CMotionGridBase::storePair: two different maps expected");
	if (!cells || cells->size() != f.cells.size())
		throw std::invalid_argument(
		    "CMotionGridBase::store: the shared cells are not the frame's");
	CMotionGridBase* const maps[2] = {&a, &b};
	const std::vector<float>* const posts[2] = {&postA, &postB};
	storeCellsOf<2>(maps, posts, f);
	a.lastCells_ = cells;
	b.lastCells_ = cells;
	a.lastPost_.swap(postA);
	b.lastPost_.swap(postB);
}

void CMotionGridBase::storeCells(const FrameCloud& f,
                                 const std::vector<float>& post)
{
	CMotionGridBase* const maps[1] = {this};
	const std::vector<float>* const posts[1] = {&post};
	storeCellsOf<1>(maps, posts, f);
}

namespace
{
// The decisions (MAP: posterior > 1/2) of N maps, bit g of one byte per
// cell (into mv, m cells): what the cells store, and a fraction of the
// posteriors' size for the readings' scattered lookups.
template <size_t N>
void decisionBits(const float* const (&post)[N], size_t m, uint8_t* mv)
{
	for (size_t i = 0; i < m; ++i)
	{
		uint8_t b = 0;
		for (size_t g = 0; g < N; ++g) b |= uint8_t((post[g][i] > 0) << g);
		mv[i] = b;
	}
}

// The decisions into the cells of the N grids: one index lookup per block
// and grid (the cells come ordered by block; a block is 512 bytes, 8 lines:
// no prefetching needed). The readings of cells over the memory budget are
// counted in st[g].
template <size_t N, class Storage>
void storeDecisions(Storage* const (&grids)[N], const FrameCloud& f,
                    const uint8_t* mv, FrameStats (&st)[N])
{
	const uint32_t* hits = f.hits.data();
	uint64_t lastKey = FlatHashMap::kEmpty;
	typename Storage::Block* last[N] = {};
	for (size_t i = 0; i < f.cells.size(); ++i)
	{
		const VoxelKey& k = f.cells[i];
		const uint64_t bk = Storage::blockKeyOf(k.x, k.y, k.z);
		if (bk != lastKey)
		{
			for (size_t g = 0; g < N; ++g)
			{
				const uint32_t b = grids[g]->findOrCreateBlock(bk);
				last[g] =
				    b == FlatHashMap::kNotFound ? nullptr : &grids[g]->block(b);
			}
			lastKey = bk;
		}
		const size_t ci = Storage::cellIndexOf(k.x, k.y, k.z);
		for (size_t g = 0; g < N; ++g)
		{
			if (!last[g])
			{
				st[g].overBudget += hits[i];
				continue;
			}
			last[g]->cells[ci].moving = uint8_t((mv[i] >> g) & 1);
		}
	}
}

// The decisions into the pixel masks of the N grids: every reading has its
// own pixel, written without a branch on the (unpredictable) decision.
template <size_t N>
void maskDecisions(const FrameCloud& f, const uint8_t* mv,
                   uint8_t* const (&mask)[N])
{
	const uint32_t* cop = f.cellOfPoint.data();
	const uint32_t* pix = f.pixel.data();
	const size_t n = f.pixel.size();
	for (size_t j = 0; j < n; ++j)
	{
		const uint32_t p = pix[j];
		const uint8_t b = mv[cop[j]];
		for (size_t g = 0; g < N; ++g)
			mask[g][p] = uint8_t(-uint8_t((b >> g) & 1));
	}
}
}  // namespace

template <size_t N>
void CMotionGridBase::storeCellsOf(CMotionGridBase* const (&maps)[N],
                                   const std::vector<float>* const (&posts)[N],
                                   const FrameCloud& f)
{
	for (size_t g = 0; g < N; ++g)
		if (posts[g]->size() != f.cells.size())
			throw std::invalid_argument(
			    "CMotionGridBase::store: one posterior per frame cell "
			    "expected");
	FrameStats st[N];
	const float* post[N];
	Storage* grids[N];
	for (size_t g = 0; g < N; ++g)
	{
		post[g] = posts[g]->data();
		grids[g] = &maps[g]->grid_;
	}
	auto& mvv = maps[0]->movingBits_;
	mvv.resize(f.cells.size());
	decisionBits(post, f.cells.size(), mvv.data());
	storeDecisions(grids, f, mvv.data(), st);
	if (f.K.width > 0 && f.K.height > 0)
	{
		uint8_t* mask[N];
		for (size_t g = 0; g < N; ++g)
		{
			maps[g]->lastMask_.reset(f.K.width, f.K.height);
			mask[g] = maps[g]->lastMask_.data.data();
		}
		maskDecisions(f, mvv.data(), mask);
	}
	else
		for (size_t g = 0; g < N; ++g) maps[g]->lastMask_.reset(0, 0);
	for (size_t g = 0; g < N; ++g)
	{
		maps[g]->frameCount_ = maps[g]->frameCount_ + 1;
		maps[g]->lastTimestamp_ = f.timestamp;
		if (st[g].overBudget) maps[g]->accountFrame(st[g]);
	}
}

std::optional<double> CMotionGridBase::probabilityAt(
    const mrpt::math::TPoint3D& p) const
{
	if (frameCount_ == 0) return std::nullopt;
	const VoxelKey k = keyOf(p);
	// Never stored (never hit, or left out by the memory budget): no
	// search.
	if (!grid_.find(k)) return std::nullopt;
	const auto& cells = *lastCells_;
	for (size_t i = 0; i < cells.size(); ++i)
		if (cells[i] == k) return sigmoid(lastPost_[i]);
	return std::nullopt;
}

bool CMotionGridBase::wasMovingAtLastHit(const VoxelKey& k) const
{
	const Cell* c = grid_.find(k);
	return c && c->moving;
}

std::vector<mrpt::math::TPoint3D> CMotionGridBase::movingCells() const
{
	std::vector<mrpt::math::TPoint3D> out;
	forEachMovingCell([&](const VoxelKey& k, float)
	                  { out.push_back(centerOf(k)); });
	return out;
}

bool CMotionGridBase::internal_insertObservation(
    const mrpt::obs::CObservation& obs,
    const std::optional<const mrpt::poses::CPose3D>& robotPose)
{
	FrameCloud f;
	if (!buildFrameOf(obs, robotPose, f)) return false;
	std::vector<float> prior, post;
	occupancySource().priorLogOdds(f, prior);
	if (!linked_) private_->integrate(f);
	computePosterior(f, prior, post);
	store(f, post);
	return true;
}

void CMotionGridBase::internal_clear()
{
	grid_.clear();
	lastPost_.clear();
	ownCells().clear();
	lastMask_.reset(0, 0);
	if (private_) private_->clear();
	clearBase();
}

void CMotionGridBase::writeMotion(mrpt::serialization::CArchive& out) const
{
	writeBase(out);
	const uint64_t nb = grid_.numBlocks();
	out << nb;
	constexpr size_t N = Storage::kCellsPerBlock;
	std::vector<uint8_t> mv(N);
	for (size_t b = 0; b < nb; ++b)
	{
		const auto& blk = grid_.block(b);
		for (size_t c = 0; c < N; ++c) mv[c] = blk.cells[c].moving;
		out << grid_.blockKey(b);
		out.WriteBuffer(mv.data(), N);
	}
	// Last frame (masks can be recomputed only with the frame; keep the
	// posteriors and keys, and the mask itself).
	const auto& cells = *lastCells_;
	out << uint64_t(cells.size());
	for (size_t i = 0; i < cells.size(); ++i)
		out << cells[i].x << cells[i].y << cells[i].z << lastPost_[i];
	out << int32_t(lastMask_.width) << int32_t(lastMask_.height);
	if (!lastMask_.data.empty())
		out.WriteBuffer(lastMask_.data.data(), lastMask_.data.size());
	// The private tier-0 map, if this map owns one.
	const bool hasPrivate = !linked_ && private_ && !private_->isEmpty();
	out << hasPrivate;
	if (hasPrivate) out << *private_;
}

void CMotionGridBase::readMotion(mrpt::serialization::CArchive& in,
                                 uint8_t version)
{
	grid_.clear();
	// Version 3 changed the cells, 4 added a parameter (raycast_margin), 5
	// wrote the parameters as key = value rows (readBase's layout 4).
	readBase(in, version >= 5   ? 4
	             : version >= 4 ? 3
	                            : std::min<uint8_t>(version, 2));
	grid_.setMaxBytes(size_t(params_.max_memory_mb * 1048576.0));
	uint64_t nb;
	in >> nb;
	constexpr size_t N = Storage::kCellsPerBlock;
	std::vector<float> l(N);
	std::vector<uint32_t> st(N);
	std::vector<uint8_t> mv(N);
	for (uint64_t b = 0; b < nb; ++b)
	{
		uint64_t key;
		in >> key;
		if (version >= 3)
			in.ReadBuffer(mv.data(), N);
		else
		{
			// Up to version 2 a cell held the posterior log-odds at its last
			// hit and the frame of that hit: the decision is its sign.
			in.ReadBufferFixEndianness(l.data(), N);
			in.ReadBufferFixEndianness(st.data(), N);
			for (size_t c = 0; c < N; ++c) mv[c] = l[c] > 0;
		}
		const uint32_t id = grid_.findOrCreateBlock(key);
		if (id == FlatHashMap::kNotFound)
			throw std::runtime_error(
			    "bims::maps: serialised map exceeds max_memory_mb");
		auto& blk = grid_.block(id);
		for (size_t c = 0; c < N; ++c) blk.cells[c].moving = mv[c] != 0;
	}
	uint64_t nl;
	in >> nl;
	if (nl > (uint64_t(1) << 32))
		throw std::runtime_error("bims::maps: corrupt serialised grid");
	auto& cells = ownCells();
	cells.resize(nl);
	lastPost_.resize(nl);
	for (size_t i = 0; i < nl; ++i)
		in >> cells[i].x >> cells[i].y >> cells[i].z >> lastPost_[i];
	int32_t w, h;
	in >> w >> h;
	if (w < 0 || h < 0 || int64_t(w) * h > (int64_t(1) << 28))
		throw std::runtime_error("bims::maps: corrupt serialised mask size");
	lastMask_.reset(w, h);
	if (!lastMask_.data.empty())
		in.ReadBuffer(lastMask_.data.data(), lastMask_.data.size());
	bool hasPrivate;
	in >> hasPrivate;
	linked_.reset();
	private_.reset();
	if (hasPrivate)
	{
		private_ = in.ReadObject<COccupancyBayesGrid>();
	}
}

void CMotionGridBase::saveMetricMapRepresentationToFile(
    const std::string& prefix) const
{
	std::vector<float> probs;
	std::vector<mrpt::math::TPoint3D> pts;
	const auto& cells = *lastCells_;
	for (size_t i = 0; i < cells.size(); ++i)
		if (lastPost_[i] > 0)
		{
			pts.push_back(centerOf(cells[i]));
			probs.push_back(float(sigmoid(lastPost_[i])));
		}
	writePointsPly(prefix + "_moving.ply", pts, probs);
}

std::string CMotionGridBase::asString() const
{
	std::ostringstream s;
	s << GetRuntimeClass()->className << ": voxel " << params_.voxel_size
	  << " m, " << frameCount_ << " frames, " << grid_.numBlocks()
	  << " blocks, last frame " << lastCells_->size() << " voxels, "
	  << movingCells().size() << " moving, O- from "
	  << (linked_ ? "a linked" : "a private") << " tier-0 map";
	return s.str();
}

void CMotionGridBase::visualize(mrpt::opengl::CSetOfObjects& o,
                                const mrpt::img::TColor& c,
                                const std::string& name) const
{
	if (!genericMapParams.enableSaveAs3DObject) return;
	addVoxelsTo(o, movingCells(), c, name);
}

}  // namespace bims::maps
