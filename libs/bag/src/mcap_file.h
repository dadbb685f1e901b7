// A ROS 2 recording in MCAP (the default storage since ROS 2 Iron), read
// by bims itself following the published MCAP specification (major version
// 0): the file mapped, its data section's records walked in file order
// (Header, Schema, Channel, Message, Chunk; index and summary records
// skipped there), each chunk's records read from its bytes, decompressed
// once ("" none, "zstd", "lz4" frames) and its uncompressed CRC checked
// when it has one. Every length is checked against the bytes there are
// before it is used. The summary section, when the footer points to a
// whole one, gives the topics' counts for --topics; the messages always
// come from the data section, so a file cut short (no summary, no footer)
// gives every whole message before the cut (docs/import-bag.md, "ROS 2").
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "chunk_cache.h"
#include "message_source.h"

namespace bims::bag
{
class McapFile : public MessageSource
{
 public:
	/** Maps \a path and walks its data section (not yet the chunks'
	 * contents). Throws std::runtime_error (not naming the file: the caller
	 * does) when it does not start with MCAP's magic; a record that does
	 * not fit later ends the walk: damage() says where. Up to \a cacheBytes
	 * of decompressed chunks are kept from the scan for message(). */
	McapFile(const std::string& path, size_t cacheBytes);
	~McapFile() override;
	McapFile(const McapFile&) = delete;
	McapFile& operator=(const McapFile&) = delete;

	void scan(const MessageFn& message) override;
	BagBytes message(const BagMessageRef& m) override;
	const std::vector<BagConnection>& connections() const override
	{
		return connections_;
	}
	std::vector<BagTopicInfo> indexTopics() const override;
	const std::string& damage() const override { return damage_; }
	bool damageLosesMessages() const override { return damageLoses_; }

	/** The chunk's index for a message outside any chunk. */
	static constexpr uint32_t kNoChunk = 0xffffffffu;

 private:
	struct Chunk
	{
		uint64_t pos = 0;      ///< its record's byte
		uint64_t data = 0;     ///< its records' byte (compressed)
		uint64_t dataLen = 0;  ///< their length in the file
		uint64_t size = 0;     ///< uncompressed
		uint32_t crc = 0;      ///< of the uncompressed bytes (0: none)
		std::string compression;
		bool cut = false;  ///< the file ends inside it (uncompressed)
	};
	using Buffer = ChunkBuffer;
	/** A record of the data section, in file order: a chunk, or a message,
	 * schema or channel outside chunks. */
	struct Item
	{
		uint8_t op = 0;
		uint64_t pos = 0;  ///< the record's byte
		uint64_t content = 0, len = 0;
		uint32_t chunk = kNoChunk;
	};

	/** The data section's records from byte 8. */
	void walk();
	/** Whether the file ends at \a pos without its footer (damage set). */
	bool cutAt(uint64_t pos);
	/** One record of the data section at \a pos; true: the walk ends
	 * there (its end, or a damage that stops it). */
	bool walkRecord(uint8_t op, uint64_t pos, uint64_t len);
	/** A chunk record; true: the walk ends there. */
	bool walkChunk(uint64_t pos, uint64_t len);
	/** The summary section, when the footer points to a whole one. */
	void readSummary();
	/** Reads a schema, channel or message record's content \a p (\a n
	 * bytes, at byte \a pos of the file or of chunk \a chunk); hands over
	 * a message. Throws saying what is wrong. */
	void record(uint8_t op, const uint8_t* p, uint64_t n, uint32_t chunk,
	            uint64_t offset, const MessageFn* message);
	Buffer decompress(const Chunk& c) const;
	BagBytes chunkBytes(size_t k) const;
	/** Hands over chunk \a k's messages; false when a record of it is
	 * damaged (damage() says which). */
	bool walkChunk(size_t k, const BagBytes& bytes, const MessageFn& message);
	void setDamage(uint64_t pos, const std::string& what, bool loses);

	std::shared_ptr<const void> map_;
	const uint8_t* bytes_ = nullptr;
	uint64_t size_ = 0;
	std::vector<Item> items_;
	std::vector<Chunk> chunks_;
	/** The schemas: id to name and encoding. */
	std::map<uint16_t, std::pair<std::string, std::string>> schemas_;
	std::vector<BagConnection> connections_;
	std::map<uint16_t, uint32_t> channelIds_;  ///< the file's id: index
	std::vector<BagTopicInfo> summary_;        ///< when the summary is whole
	std::string damage_;
	uint64_t damagePos_ = 0;
	bool damageLoses_ = false;

	ChunkCache cache_;
};

}  // namespace bims::bag
