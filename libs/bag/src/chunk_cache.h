// The decompressed chunks of a bag file (ROS 1 or MCAP) kept between the scan
// and the images: one home for the rule both readers share. A chunk the scan
// decompressed is kept while the budget allows; a chunk asked for later comes
// from there, else is decompressed again and kept as the last one; chunks
// well behind the one asked for are dropped (the messages are read in about
// the chunks' order). Thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

namespace bims::bag
{
/** One chunk's decompressed bytes. */
struct ChunkData
{
	std::unique_ptr<uint8_t[]> bytes;
	size_t n = 0;
	const uint8_t* data() const { return bytes.get(); }
	size_t size() const { return n; }
};
using ChunkBuffer = std::shared_ptr<const ChunkData>;

class ChunkCache
{
 public:
	/** \param budget bytes of chunks kept from the scan at most */
	explicit ChunkCache(size_t budget) : budget_(budget) {}

	/** Keeps chunk \a k's bytes from the scan when the budget allows. */
	void keep(uint32_t k, ChunkBuffer b)
	{
		const std::lock_guard<std::mutex> lock(mutex_);
		if (bytes_ + b->size() > budget_) return;
		bytes_ += b->size();
		kept_[k] = std::move(b);
	}

	/** Chunk \a k's bytes: kept, or \a decompress()'s, then the last one;
	 * the kept chunks well behind \a k are dropped. A std::runtime_error of
	 * \a decompress is thrown again naming the chunk's byte \a pos. */
	ChunkBuffer get(uint32_t k, uint64_t pos,
	                const std::function<ChunkBuffer()>& decompress)
	{
		{
			const std::lock_guard<std::mutex> lock(mutex_);
			const auto it = kept_.find(k);
			if (it != kept_.end()) return it->second;
			if (last_ && lastChunk_ == k) return last_;
		}
		ChunkBuffer b;
		try
		{
			b = decompress();
		}
		catch (const std::runtime_error& e)
		{
			throw std::runtime_error("the chunk at byte " +
			                         std::to_string(pos) + ": " + e.what());
		}
		const std::lock_guard<std::mutex> lock(mutex_);
		last_ = b;
		lastChunk_ = k;
		for (auto it = kept_.begin(); it != kept_.end() && it->first + 2 < k;)
		{
			bytes_ -= it->second->size();
			it = kept_.erase(it);
		}
		return b;
	}

 private:
	std::mutex mutex_;
	size_t budget_ = 0, bytes_ = 0;
	std::map<uint32_t, ChunkBuffer> kept_;  ///< from the scan
	ChunkBuffer last_;  ///< the chunk decompressed last, beyond the budget
	uint32_t lastChunk_ = 0;
};

}  // namespace bims::bag
