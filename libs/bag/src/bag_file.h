// A ROS 1 bag (format 2.0) read by bims itself: the file mapped, its
// records walked in file order, each chunk decompressed once (bz2, lz4)
// and its messages handed over with their bytes. It replaces
// rosbag_storage's reading (docs/import-bag.md, "How a bag is read"):
// rosbag trusts every length and offset the file declares (five fuzz
// findings, docs/fuzz.md), refuses a bag whose index is missing (a
// recording cut short) and decompresses a chunk again for each pass.
//
// The index at the bag's end is read only to list topics (--topics); the
// messages come from the chunks themselves, so a bag cut short gives every
// whole message before the cut.
#pragma once

#include <bims/bag/bag_import.h>

#include "chunk_cache.h"
#include "message_source.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace bims::bag
{
namespace detail
{
struct BagRecord;  ///< one record as read (bag_file.cpp)
}

class BagFile : public MessageSource
{
 public:
	/** Maps \a path and walks its records (not yet the chunks' contents).
	 * Throws std::runtime_error (not naming the file: the caller does)
	 * when it is no ROS 1 bag of format 2.0 or its first record is not the
	 * bag header; a record that does not fit later ends the walk: damage()
	 * says where. Up to \a cacheBytes of decompressed BZ2 chunks are kept
	 * from the scan for message(): a bag whose chunks fit is decompressed
	 * once (LZ4 chunks are decompressed again: as fast as keeping them). */
	BagFile(const std::string& path, size_t cacheBytes);
	~BagFile() override;
	BagFile(const BagFile&) = delete;
	BagFile& operator=(const BagFile&) = delete;

	/** Every message of every chunk in file order, with its data (valid
	 * during the call), chunks decompressed ahead on a second thread. A
	 * chunk that cannot be read ends the scan (damage()); the messages
	 * before it in that chunk are handed over. Connections are known as
	 * their records come. */
	void scan(const MessageFn& message) override;

	/** The data of a message the scan handed over. Throws
	 * std::runtime_error when its chunk cannot be decompressed again. */
	BagBytes message(const BagMessageRef& m) override;

	const std::vector<BagConnection>& connections() const override
	{
		return connections_;
	}

	/** The topics the bag's index lists, with their message counts; empty
	 * when the index is missing or damaged (then scan() knows them). */
	std::vector<BagTopicInfo> indexTopics() const override;

	/** Where and why the bag stops being readable ("the record at byte N:
	 * ..."); empty when it is whole. */
	const std::string& damage() const override { return damage_; }
	/** The damage is where messages are (not only in the index at the
	 * bag's end): messages after it are lost. */
	bool damageLosesMessages() const override { return damageLoses_; }

 private:
	struct Chunk
	{
		uint64_t pos = 0;   ///< its record's byte
		uint64_t data = 0;  ///< its data's byte
		uint64_t dataLen = 0;
		uint64_t size = 0;  ///< uncompressed
		bool cut = false;   ///< the file ends inside it (uncompressed)
		enum Kind
		{
			None,
			Bz2,
			Lz4
		} kind = None;
	};
	/** A decompressed chunk: its bytes are not zeroed first (all are
	 * written), which would cost a pass over them. */
	using Buffer = ChunkBuffer;

	/** The records from byte \a start (after the version line). */
	void walk(uint64_t start);
	/** One record of the walk (\a first: the file's first); connections
	 * into \a indexTopicOf (id: topic). */
	void walkRecord(const detail::BagRecord& r, uint64_t pos, bool first,
	                std::map<uint32_t, std::string>& indexTopicOf);
	/** The topics and their counts from a whole index. */
	void indexFrom(const std::map<uint32_t, std::string>& indexTopicOf);
	void addChunk(const detail::BagRecord& r, uint64_t pos);
	/** Registers the connection record \a r (at \a pos of \a bytes) unless
	 * its id is known; returns its id. */
	uint32_t addConnection(const detail::BagRecord& r, const uint8_t* bytes,
	                       uint64_t pos);
	Buffer decompress(const Chunk& c) const;
	/** Chunk \a k's uncompressed bytes; throws saying why not. */
	BagBytes chunkBytes(size_t k) const;
	/** Hands over chunk \a k's messages; false when a record of it is
	 * damaged (damage() says which). */
	bool walkChunk(size_t k, const BagBytes& bytes, const MessageFn& message);
	/** Keeps the first damage in the file (at byte \a pos). */
	void setDamage(uint64_t pos, const std::string& what);

	std::shared_ptr<const void> map_;
	const uint8_t* bytes_ = nullptr;
	uint64_t size_ = 0;
	std::vector<Chunk> chunks_;
	std::vector<BagConnection> connections_;
	std::map<uint32_t, uint32_t> connectionIds_;  ///< the file's id: index
	/** Per chunk info record of the index: connection id, message count. */
	std::map<uint32_t, uint64_t> indexCounts_;
	uint64_t indexPos_ = 0, declaredConnections_ = 0, declaredChunks_ = 0;
	size_t chunkInfos_ = 0;
	std::vector<BagTopicInfo> index_;  ///< when the index is whole
	std::string damage_;
	uint64_t damagePos_ = 0;
	bool damageLoses_ = false;

	ChunkCache cache_;
};

}  // namespace bims::bag
