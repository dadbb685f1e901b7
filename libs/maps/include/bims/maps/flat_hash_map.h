// A small open-addressing (linear probing) hash map from 64-bit keys to
// 32-bit values, the index of the sparse voxel storage. Faster and 3x
// smaller than std::unordered_map for this use (docs/maps.md).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace bims::maps
{
using std::size_t;

class FlatHashMap
{
 public:
	static constexpr uint64_t kEmpty = ~uint64_t(0);
	static constexpr uint32_t kNotFound = ~uint32_t(0);

	explicit FlatHashMap(size_t initialCapacity = 64)
	{
		rehash(initialCapacity);
	}

	size_t size() const { return size_; }
	size_t capacity() const { return keys_.size(); }
	/** Bytes held by the table. */
	size_t memoryBytes() const
	{
		return keys_.capacity() * sizeof(uint64_t) +
		       vals_.capacity() * sizeof(uint32_t);
	}

	/** Value of \a key, or kNotFound. */
	uint32_t find(uint64_t key) const
	{
		size_t i = slot(key);
		for (;;)
		{
			const uint64_t k = keys_[i];
			if (k == key) return vals_[i];
			if (k == kEmpty) return kNotFound;
			i = (i + 1) & mask_;
		}
	}

	/** Inserts (key, value) if absent. Returns the stored value and whether
	 * it was inserted. */
	std::pair<uint32_t, bool> insert(uint64_t key, uint32_t value)
	{
		if ((size_ + 1) * 2 > keys_.size()) rehash(keys_.size() * 2);
		size_t i = slot(key);
		for (;;)
		{
			const uint64_t k = keys_[i];
			if (k == key) return {vals_[i], false};
			if (k == kEmpty)
			{
				keys_[i] = key;
				vals_[i] = value;
				++size_;
				return {value, true};
			}
			i = (i + 1) & mask_;
		}
	}

	/** Removes every entry, keeping the capacity. */
	void clear()
	{
		std::fill(keys_.begin(), keys_.end(), kEmpty);
		size_ = 0;
	}

	/** Calls f(key, value) for every entry (unspecified order). */
	template <class F>
	void forEach(F&& f) const
	{
		for (size_t i = 0; i < keys_.size(); ++i)
			if (keys_[i] != kEmpty) f(keys_[i], vals_[i]);
	}

 private:
	size_t slot(uint64_t key) const
	{
		return size_t((key * 0x9E3779B97F4A7C15ull) >> shift_);
	}
	void rehash(size_t cap)
	{
		size_t c = 16;
		unsigned bits = 4;
		while (c < cap)
		{
			c <<= 1;
			++bits;
		}
		std::vector<uint64_t> oldK(c, kEmpty);
		std::vector<uint32_t> oldV(c);
		oldK.swap(keys_);
		oldV.swap(vals_);
		mask_ = c - 1;
		shift_ = 64 - bits;
		size_ = 0;
		for (size_t i = 0; i < oldK.size(); ++i)
			if (oldK[i] != kEmpty) insert(oldK[i], oldV[i]);
	}

	std::vector<uint64_t> keys_;
	std::vector<uint32_t> vals_;
	size_t mask_ = 0;
	unsigned shift_ = 60;
	size_t size_ = 0;
};

}  // namespace bims::maps
