// Sparse, unbounded voxel storage shared by the three grids: hashed blocks
// of (2^Log2Dim)^3 cells (a two-level structure in the spirit of VDB leaves
// and Bonxai's inner grids, with a flat hash map as the root). Log2Dim = 3
// (8^3 blocks) was chosen by measurement (docs/maps.md, bench_maps).
#pragma once

#include <bims/maps/flat_hash_map.h>
#include <bims/maps/voxel_key.h>

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace bims::maps
{
template <class Cell, int Log2Dim = 3>
class SparseVoxelGrid
{
 public:
	static constexpr int kDim = 1 << Log2Dim;
	static constexpr int kMask = kDim - 1;
	static constexpr size_t kCellsPerBlock = size_t(kDim) * kDim * kDim;
	struct Block
	{
		Cell cells[kCellsPerBlock];
	};

	/** \param maxBytes budget for blocks + index; beyond it findOrCreate()
	 * returns nullptr. */
	explicit SparseVoxelGrid(size_t maxBytes = size_t(1) << 40)
	    : maxBytes_(maxBytes)
	{
	}
	SparseVoxelGrid(const SparseVoxelGrid& o) { *this = o; }
	SparseVoxelGrid& operator=(const SparseVoxelGrid& o)
	{
		if (this == &o) return *this;
		maxBytes_ = o.maxBytes_;
		index_ = o.index_;
		blockKeys_ = o.blockKeys_;
		blocks_.clear();
		for (const auto& b : o.blocks_)
			blocks_.push_back(std::make_unique<Block>(*b));
		return *this;
	}

	static uint64_t blockKeyOf(int32_t x, int32_t y, int32_t z)
	{
		return packKey(x >> Log2Dim, y >> Log2Dim, z >> Log2Dim);
	}
	static size_t cellIndexOf(int32_t x, int32_t y, int32_t z)
	{
		return size_t(x & kMask) | (size_t(y & kMask) << Log2Dim) |
		       (size_t(z & kMask) << (2 * Log2Dim));
	}

	/** Cell at \a k, or nullptr if its block does not exist. */
	const Cell* find(const VoxelKey& k) const
	{
		const uint32_t b = index_.find(blockKeyOf(k.x, k.y, k.z));
		if (b == FlatHashMap::kNotFound) return nullptr;
		return &blocks_[b]->cells[cellIndexOf(k.x, k.y, k.z)];
	}
	Cell* find(const VoxelKey& k)
	{
		return const_cast<Cell*>(std::as_const(*this).find(k));
	}

	/** Block index for a block key, creating the block (cells
	 * default-constructed) if needed; FlatHashMap::kNotFound if the memory
	 * budget forbids it. */
	uint32_t findOrCreateBlock(uint64_t blockKey)
	{
		const uint32_t b = index_.find(blockKey);
		if (b != FlatHashMap::kNotFound) return b;
		if (memoryBytes() + sizeof(Block) > maxBytes_)
			return FlatHashMap::kNotFound;
		const uint32_t id = uint32_t(blocks_.size());
		blocks_.push_back(std::make_unique<Block>());
		blockKeys_.push_back(blockKey);
		index_.insert(blockKey, id);
		return id;
	}

	/** Cell at \a k, creating its block if needed; nullptr over budget. */
	Cell* findOrCreate(const VoxelKey& k)
	{
		const uint32_t b = findOrCreateBlock(blockKeyOf(k.x, k.y, k.z));
		if (b == FlatHashMap::kNotFound) return nullptr;
		return &blocks_[b]->cells[cellIndexOf(k.x, k.y, k.z)];
	}

	/** The cell of each of \a keys, created if needed (nullptr where the
	 * memory budget forbids its block), with one index lookup per run of
	 * keys in one block (FrameCloud::cells are sorted by block). Blocks are
	 * created in the order of the keys, as by an Accessor. */
	void resolve(const std::vector<VoxelKey>& keys, std::vector<Cell*>& out)
	{
		out.resize(keys.size());
		uint64_t lastKey = FlatHashMap::kEmpty;
		Block* last = nullptr;
		for (size_t i = 0; i < keys.size(); ++i)
		{
			const VoxelKey& k = keys[i];
			const uint64_t bk = blockKeyOf(k.x, k.y, k.z);
			if (bk != lastKey)
			{
				const uint32_t b = findOrCreateBlock(bk);
				last = b == FlatHashMap::kNotFound ? nullptr : blocks_[b].get();
				lastKey = bk;
			}
			out[i] = last ? &last->cells[cellIndexOf(k.x, k.y, k.z)] : nullptr;
		}
	}

	/** Block with packed key \a blockKey, or nullptr (never creates). */
	const Block* findBlock(uint64_t blockKey) const
	{
		const uint32_t b = index_.find(blockKey);
		return b == FlatHashMap::kNotFound ? nullptr : blocks_[b].get();
	}
	Block* findBlock(uint64_t blockKey)
	{
		return const_cast<Block*>(std::as_const(*this).findBlock(blockKey));
	}

	size_t numBlocks() const { return blocks_.size(); }
	size_t numCells() const { return blocks_.size() * kCellsPerBlock; }
	Block& block(size_t i) { return *blocks_[i]; }
	const Block& block(size_t i) const { return *blocks_[i]; }
	/** Packed block coordinates of block i (see blockKeyOf()). */
	uint64_t blockKey(size_t i) const { return blockKeys_[i]; }
	/** Voxel key of the first (lowest) cell of block i. */
	VoxelKey blockOrigin(size_t i) const
	{
		const VoxelKey b = unpackKey(blockKeys_[i]);
		return {b.x * kDim, b.y * kDim, b.z * kDim};
	}
	/** Voxel key of cell c of block i. */
	VoxelKey cellKey(size_t i, size_t c) const
	{
		const VoxelKey o = blockOrigin(i);
		return {o.x + int32_t(c & kMask), o.y + int32_t((c >> Log2Dim) & kMask),
		        o.z + int32_t(c >> (2 * Log2Dim))};
	}

	/** Calls f(key, cell) for every stored cell. */
	template <class F>
	void forEachCell(F&& f) const
	{
		for (size_t i = 0; i < blocks_.size(); ++i)
			for (size_t c = 0; c < kCellsPerBlock; ++c)
				f(cellKey(i, c), blocks_[i]->cells[c]);
	}

	void clear()
	{
		blocks_.clear();
		blockKeys_.clear();
		index_ = FlatHashMap();
	}

	/** Bytes used by blocks and index. */
	size_t memoryBytes() const
	{
		return blocks_.size() * (sizeof(Block) + sizeof(void*) + 8) +
		       index_.memoryBytes();
	}
	size_t maxBytes() const { return maxBytes_; }
	void setMaxBytes(size_t b) { maxBytes_ = b; }

	/** Fast repeated access along a path (rays): caches the last block. */
	class Accessor
	{
	 public:
		explicit Accessor(SparseVoxelGrid& g) : g_(g) {}
		/** Cell at voxel (x, y, z), created if needed; nullptr over budget. */
		Cell* get(int32_t x, int32_t y, int32_t z)
		{
			const uint64_t bk = blockKeyOf(x, y, z);
			if (bk != lastKey_ || !last_)
			{
				const uint32_t b = g_.findOrCreateBlock(bk);
				last_ = (b == FlatHashMap::kNotFound) ? nullptr
				                                      : g_.blocks_[b].get();
				lastKey_ = bk;
				if (!last_) return nullptr;
			}
			return &last_->cells[cellIndexOf(x, y, z)];
		}

		/** Hints the CPU to fetch the cell at (x, y, z) for writing, if its
		 * block exists (never creates one): call it some cells ahead of
		 * get() when walking a long list of cells whose blocks are out of
		 * cache. */
		void prefetch(int32_t x, int32_t y, int32_t z)
		{
			const uint64_t bk = blockKeyOf(x, y, z);
			if (bk != peekKey_)
			{
				const uint32_t b = g_.index_.find(bk);
				peek_ =
				    b == FlatHashMap::kNotFound ? nullptr : g_.blocks_[b].get();
				peekKey_ = bk;
			}
#if defined(__GNUC__)
			if (peek_)
				__builtin_prefetch(&peek_->cells[cellIndexOf(x, y, z)], 1);
#endif
		}

	 private:
		SparseVoxelGrid& g_;
		uint64_t lastKey_ = FlatHashMap::kEmpty;
		Block* last_ = nullptr;
		uint64_t peekKey_ = FlatHashMap::kEmpty;
		Block* peek_ = nullptr;
	};

 private:
	size_t maxBytes_;
	FlatHashMap index_;
	std::vector<uint64_t> blockKeys_;
	std::vector<std::unique_ptr<Block>> blocks_;
};

}  // namespace bims::maps
