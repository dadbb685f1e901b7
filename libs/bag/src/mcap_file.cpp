#include "mcap_file.h"

#include <libdeflate.h>
#include <lz4frame.h>
#include <mrpt/core/format.h>
#include <zstd.h>

#include <cstring>
#include <deque>
#include <future>
#include <stdexcept>

#include "mapped_file.h"

namespace bims::bag
{
namespace
{
using std::runtime_error;

constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr uint64_t kMaxChunk = uint64_t{1} << 30;  // a few MB in practice

enum Op : uint8_t
{
	kHeader = 0x01,
	kFooter = 0x02,
	kSchema = 0x03,
	kChannel = 0x04,
	kMessage = 0x05,
	kChunk = 0x06,
	kStatistics = 0x0b,
	kDataEnd = 0x0f
};

std::string at(uint64_t pos)
{
	return "the record at byte " + std::to_string(pos);
}

/** Reads a record's fields (little-endian) in order, each length checked
 * against the bytes left. */
class Cursor
{
 public:
	Cursor(const uint8_t* p, uint64_t n) : p_(p), n_(n) {}
	uint64_t left() const { return n_ - i_; }
	uint64_t offset() const { return i_; }
	const uint8_t* here() const { return p_ + i_; }
	uint64_t uint(size_t bytes, const char* what)
	{
		need(bytes, what);
		uint64_t v = 0;
		for (size_t k = bytes; k-- > 0;) v = v << 8 | p_[i_ + k];
		i_ += bytes;
		return v;
	}
	uint16_t u16(const char* what)
	{
		return static_cast<uint16_t>(uint(2, what));
	}
	uint32_t u32(const char* what)
	{
		return static_cast<uint32_t>(uint(4, what));
	}
	uint64_t u64(const char* what) { return uint(8, what); }
	/** \a k bytes, skipped: where they are. */
	const uint8_t* take(uint64_t k, const char* what)
	{
		need(k, what);
		const uint8_t* at = p_ + i_;
		i_ += k;
		return at;
	}
	std::string string(const char* what)
	{
		const uint32_t k = u32(what);
		return std::string(reinterpret_cast<const char*>(take(k, what)), k);
	}
	/** A map or array: its byte length, then its bytes. */
	Cursor sub32(const char* what)
	{
		const uint32_t k = u32(what);
		return Cursor(take(k, what), k);
	}

 private:
	void need(uint64_t k, const char* what)
	{
		if (k > n_ - i_)
			throw runtime_error(mrpt::format(
			    "its %s declares or needs %llu bytes, %llu are left", what,
			    static_cast<unsigned long long>(k),
			    static_cast<unsigned long long>(n_ - i_)));
	}
	const uint8_t* p_;
	uint64_t n_, i_ = 0;
};

/** MCAP's CRC: CRC-32 (ISO-HDLC, zlib's), by libdeflate (several times
 * zlib's speed where the processor has carry-less multiplication). */
uint32_t crc32Of(const uint8_t* p, uint64_t n)
{
	return libdeflate_crc32(0, p, static_cast<size_t>(n));
}

/** The channel of a message: id to index (or an error). */
uint32_t channelIndex(const std::map<uint16_t, uint32_t>& ids, uint16_t id)
{
	const auto it = ids.find(id);
	if (it == ids.end())
		throw runtime_error("a message on channel " + std::to_string(id) +
		                    ", which no channel record before it defines");
	return it->second;
}
}  // namespace

McapFile::McapFile(const std::string& path, size_t cacheBytes)
    : cache_(cacheBytes)
{
	const MappedFile f = mapFile(path);
	map_ = f.owner;
	bytes_ = f.bytes;
	size_ = f.size;
	if (size_ < sizeof(kMagic) || std::memcmp(bytes_, kMagic, 8) != 0)
		throw runtime_error(
		    size_ >= 5 && std::memcmp(bytes_, kMagic, 5) == 0
		        ? "MCAP of another major version than 0 (its magic): not read"
		        : "not an MCAP file (it does not start with MCAP's magic)");
	walk();
	readSummary();
}

McapFile::~McapFile() = default;

void McapFile::setDamage(uint64_t pos, const std::string& what, bool loses)
{
	if (!damage_.empty() && pos >= damagePos_) return;  // the first
	damage_ = what;
	damagePos_ = pos;
	damageLoses_ = loses;
}

void McapFile::record(uint8_t op, const uint8_t* p, uint64_t n, uint32_t chunk,
                      uint64_t offset, const MessageFn* message)
{
	Cursor c(p, n);
	if (op == kSchema)
	{
		const uint16_t id = c.u16("id");
		std::string name = c.string("name");
		std::string encoding = c.string("encoding");
		c.sub32("data");
		if (id != 0 && !schemas_.count(id))
			schemas_[id] = {std::move(name), std::move(encoding)};
	}
	else if (op == kChannel)
	{
		const uint16_t id = c.u16("id");
		const uint16_t schema = c.u16("schema_id");
		BagConnection b;
		b.topic = c.string("topic");
		const std::string encoding = c.string("message_encoding");
		c.sub32("metadata");
		if (channelIds_.count(id)) return;  // repeated (chunks, summary)
		b.wire = Wire::Cdr;
		const std::string name =
		    "channel " + std::to_string(id) + " (" + b.topic + ")";
		const auto s = schemas_.find(schema);
		if (s == schemas_.end())
		{
			b.type = "(no schema)";
			b.unreadable = name + ": its schema " + std::to_string(schema) +
			               (schema == 0 ? " (none)" : " is not defined") +
			               ": its messages' type is not known";
		}
		else
		{
			b.type = s->second.first;
			if (s->second.second != "ros2msg")
				b.unreadable = name + ": its schema's encoding is '" +
				               s->second.second +
				               "', not ROS 2's ros2msg: not read";
		}
		if (b.unreadable.empty() && encoding != "cdr")
			b.unreadable = name + ": its message encoding is '" + encoding +
			               "', not ROS 2's cdr: not read";
		channelIds_[id] = static_cast<uint32_t>(connections_.size());
		connections_.push_back(std::move(b));
	}
	else if (op == kMessage && message)
	{
		BagMessageRef ref;
		ref.connection = channelIndex(channelIds_, c.u16("channel_id"));
		c.u32("sequence");
		ref.time = c.u64("log_time");
		c.u64("publish_time");
		if (c.left() > 0xffffffffu)
			throw runtime_error("a message of more than 4 GB");
		ref.chunk = chunk;
		ref.offset = offset + c.offset();
		ref.size = static_cast<uint32_t>(c.left());
		(*message)(ref, c.here());
	}
}

bool McapFile::cutAt(uint64_t pos)
{
	if (pos == size_)
		setDamage(pos,
		          "it ends at byte " + std::to_string(pos) +
		              " without its data section's end (DataEnd) and "
		              "footer: cut short",
		          true);
	else if (size_ - pos < 9)
		setDamage(pos,
		          at(pos) +
		              ": the file ends inside its opcode and "
		              "length: cut short",
		          true);
	else
		return false;
	return true;
}

void McapFile::walk()
{
	uint64_t pos = sizeof(kMagic);
	bool first = true;
	while (!cutAt(pos))
	{
		const uint8_t op = bytes_[pos];
		uint64_t len = 0;
		for (int k = 8; k-- > 0;) len = len << 8 | bytes_[pos + 1 + k];
		const uint64_t content = pos + 9;
		if (first && op != kHeader)
			throw runtime_error(mrpt::format(
			    "its first record (opcode 0x%02x) is not MCAP's Header", op));
		first = false;
		try
		{
			if (walkRecord(op, pos, len)) return;
		}
		catch (const std::exception& e)
		{
			setDamage(
			    pos,
			    at(pos) + mrpt::format(" (opcode 0x%02x): ", op) + e.what(),
			    true);
			return;
		}
		pos = content + len;
	}
}

bool McapFile::walkRecord(uint8_t op, uint64_t pos, uint64_t len)
{
	const uint64_t content = pos + 9;
	const uint64_t left = size_ - content;
	if (len > left && op != kChunk)
		throw runtime_error(
		    mrpt::format("it declares %llu bytes, %llu follow",
		                 static_cast<unsigned long long>(len),
		                 static_cast<unsigned long long>(left)));
	Cursor c(bytes_ + content, std::min(len, left));
	switch (op)
	{
		case kHeader:
			c.string("profile");
			c.string("library");
			return false;
		case kSchema:
		case kChannel:
			record(op, bytes_ + content, len, kNoChunk, 0, nullptr);
			return false;
		case kMessage:
			// checked now, handed over by scan()
			Cursor(bytes_ + content, len).take(22, "message header");
			items_.push_back({op, pos, content, len, kNoChunk});
			return false;
		case kChunk:
			return walkChunk(pos, len);
		case kDataEnd:
		{
			const uint32_t crc = c.u32("data_section_crc");
			if (crc != 0 && crc32Of(bytes_, pos) != crc)
				setDamage(pos,
				          at(pos) +
				              " (DataEnd): the data section's CRC "
				              "does not match its bytes: damaged",
				          true);
			return true;
		}
		case kFooter:
			return true;
		default:
			return false;  // index, attachment, metadata: not needed
	}
}

bool McapFile::walkChunk(uint64_t pos, uint64_t len)
{
	const uint64_t content = pos + 9;
	const uint64_t left = size_ - content;
	Cursor c(bytes_ + content, std::min(len, left));
	Chunk ch;
	ch.pos = pos;
	c.u64("message_start_time");
	c.u64("message_end_time");
	ch.size = c.u64("uncompressed_size");
	ch.crc = c.u32("uncompressed_crc");
	ch.compression = c.string("compression");
	ch.dataLen = c.u64("records' length");
	ch.data = content + c.offset();
	if (len > left || ch.dataLen > c.left())
	{
		// cut: an uncompressed chunk's whole records are read
		ch.cut = true;
		const uint64_t declared = ch.dataLen;
		ch.dataLen = std::min(ch.dataLen, c.left());
		const auto u = [](uint64_t v)
		{ return static_cast<unsigned long long>(v); };
		setDamage(pos,
		          len > left ? mrpt::format("the chunk at byte %llu: it "
		                                    "declares %llu bytes, %llu "
		                                    "follow",
		                                    u(pos), u(len), u(left))
		                     : mrpt::format("the chunk at byte %llu: its "
		                                    "records declare %llu bytes, "
		                                    "the chunk has %llu left: "
		                                    "corrupt",
		                                    u(pos), u(declared), u(ch.dataLen)),
		          true);
		if (!ch.compression.empty()) return true;
	}
	items_.push_back(
	    {kChunk, pos, content, len, static_cast<uint32_t>(chunks_.size())});
	chunks_.push_back(ch);
	return ch.cut;
}

namespace
{
/** The summary section's schemas, channels and message counts. */
struct SummaryRecords
{
	std::map<uint16_t, std::pair<std::string, std::string>> schemas;
	std::map<uint16_t, std::pair<std::string, std::string>> channels;
	std::map<uint16_t, uint64_t> counts;
	bool stats = false;  ///< a Statistics record was read

	void add(uint8_t op, Cursor& r)
	{
		if (op == kSchema)
		{
			const uint16_t id = r.u16("id");
			std::string name = r.string("name");
			schemas[id] = {name, r.string("encoding")};
		}
		else if (op == kChannel)
		{
			const uint16_t id = r.u16("id");
			const uint16_t schema = r.u16("schema_id");
			std::string topic = r.string("topic");
			const auto s = schemas.find(schema);
			channels[id] = {
			    topic, s == schemas.end() ? "(no schema)" : s->second.first};
		}
		else if (op == kStatistics)
		{
			r.u64("message_count");
			r.u16("schema_count");
			for (const char* w : {"channel_count", "attachment_count",
			                      "metadata_count", "chunk_count"})
				r.u32(w);
			r.u64("message_start_time");
			r.u64("message_end_time");
			Cursor m = r.sub32("channel_message_counts");
			while (m.left() > 0)
			{
				const uint16_t id = m.u16("channel id");
				counts[id] += m.u64("count");
			}
			stats = true;
		}
	}
	/** Per topic: its type and its messages over its channels. */
	std::vector<BagTopicInfo> topics() const
	{
		std::map<std::string, BagTopicInfo> byName;
		for (const auto& [id, ch] : channels)
		{
			auto& t = byName[ch.first];
			t.name = ch.first;
			if (t.type.empty()) t.type = ch.second;
			const auto n = counts.find(id);
			t.messages += n == counts.end() ? 0 : n->second;
		}
		std::vector<BagTopicInfo> out;
		for (auto& [name, t] : byName) out.push_back(t);
		return out;
	}
};
}  // namespace

void McapFile::readSummary()
{
	// <Footer record: 9 + 20 bytes><magic>
	constexpr uint64_t kFooterRec = 9 + 20;
	if (size_ < 8 + kFooterRec + 8 ||
	    std::memcmp(bytes_ + size_ - 8, kMagic, 8) != 0)
		return;
	const uint64_t footer = size_ - 8 - kFooterRec;
	Cursor f(bytes_ + footer, kFooterRec);
	if (f.uint(1, "opcode") != kFooter || f.u64("length") != 20) return;
	const uint64_t start = f.u64("summary_start");
	const uint64_t offsets = f.u64("summary_offset_start");
	const uint32_t crc = f.u32("summary_crc");
	if (start < 8 || start > footer) return;  // none
	if (crc != 0 && crc32Of(bytes_ + start, footer + 9 + 16 - start) != crc)
		return;  // counted in the chunks then
	const uint64_t end = offsets >= start && offsets <= footer ? offsets
	                     : offsets == 0                        ? footer
	                                                           : start;
	SummaryRecords records;
	try
	{
		uint64_t pos = start;
		while (pos < end)
		{
			if (end - pos < 9) return;
			const uint8_t op = bytes_[pos];
			uint64_t len = 0;
			for (int k = 8; k-- > 0;) len = len << 8 | bytes_[pos + 1 + k];
			if (len > end - pos - 9) return;
			Cursor r(bytes_ + pos + 9, len);
			records.add(op, r);
			pos += 9 + len;
		}
	}
	catch (const std::exception&)
	{
		return;  // a damaged summary: the chunks are counted instead
	}
	if (records.stats) summary_ = records.topics();
}

std::vector<BagTopicInfo> McapFile::indexTopics() const
{
	// the summary of a file damaged in its data would count lost messages
	if (damageLoses_) return {};
	return summary_;
}

McapFile::Buffer McapFile::decompress(const Chunk& c) const
{
	if (c.size > kMaxChunk)
		throw runtime_error(
		    mrpt::format("it declares %llu uncompressed bytes: more than 1 GiB",
		                 static_cast<unsigned long long>(c.size)));
	const uint8_t* src = bytes_ + c.data;
	auto out = std::make_shared<ChunkData>();
	out->n = static_cast<size_t>(c.size);
	if (c.compression == "zstd")
	{
		const unsigned long long declared =
		    ZSTD_getFrameContentSize(src, c.dataLen);
		if (declared == ZSTD_CONTENTSIZE_ERROR)
			throw runtime_error("its zstd data is not a zstd frame: corrupt");
		if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != c.size)
			throw runtime_error(mrpt::format(
			    "its zstd frame holds %llu bytes, the chunk declares %llu: "
			    "corrupt",
			    declared, static_cast<unsigned long long>(c.size)));
		// (not zeroed: every byte is written, or it is an error)
		out->bytes.reset(new uint8_t[std::max<size_t>(out->n, 1)]);
		const size_t got =
		    ZSTD_decompress(out->bytes.get(), out->n, src, c.dataLen);
		if (ZSTD_isError(got))
			throw runtime_error(std::string("zstd: ") + ZSTD_getErrorName(got) +
			                    ": corrupt");
		if (got != out->n)
			throw runtime_error(mrpt::format(
			    "it decompresses to %zu bytes, it declares %zu: corrupt", got,
			    out->n));
	}
	else if (c.compression == "lz4")
	{
		LZ4F_dctx* ctx = nullptr;
		if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION)))
			throw runtime_error("lz4: no decompression context");
		const std::unique_ptr<LZ4F_dctx, size_t (*)(LZ4F_dctx*)> hold(
		    ctx, LZ4F_freeDecompressionContext);
		out->bytes.reset(new uint8_t[std::max<size_t>(out->n, 1)]);
		size_t used = 0, done = 0, hint = 1;
		while (hint != 0)
		{
			size_t srcLen = static_cast<size_t>(c.dataLen) - used;
			size_t dstLen = out->n - done;
			hint = LZ4F_decompress(ctx, out->bytes.get() + done, &dstLen,
			                       src + used, &srcLen, nullptr);
			if (LZ4F_isError(hint))
				throw runtime_error(std::string("lz4: ") +
				                    LZ4F_getErrorName(hint) + ": corrupt");
			used += srcLen;
			done += dstLen;
			if (hint != 0 && srcLen == 0 && dstLen == 0)
				throw runtime_error(mrpt::format(
				    "its lz4 frame %s: corrupt",
				    used == c.dataLen ? "ends early"
				                      : "holds more than it declares"));
		}
		if (done != out->n || used != c.dataLen)
			throw runtime_error(mrpt::format(
			    "it decompresses to %zu bytes of %zu, it declares %zu: "
			    "corrupt",
			    done, used, out->n));
	}
	else
		throw runtime_error("its compression '" + c.compression +
		                    "' is not MCAP's zstd or lz4: not read");
	if (c.crc != 0 && crc32Of(out->bytes.get(), out->n) != c.crc)
		throw runtime_error(
		    mrpt::format("its uncompressed CRC 0x%08x does not match its "
		                 "records' (0x%08x): damaged",
		                 c.crc, crc32Of(out->bytes.get(), out->n)));
	return out;
}

BagBytes McapFile::chunkBytes(size_t k) const
{
	const Chunk& c = chunks_[k];
	if (!c.compression.empty())
	{
		Buffer b = decompress(c);
		return {b, b->bytes.get(), b->n};
	}
	if (!c.cut && c.dataLen != c.size)
		throw runtime_error(mrpt::format(
		    "uncompressed, it declares %llu bytes of records and has %llu: "
		    "corrupt",
		    static_cast<unsigned long long>(c.size),
		    static_cast<unsigned long long>(c.dataLen)));
	if (!c.cut && c.crc != 0 && crc32Of(bytes_ + c.data, c.dataLen) != c.crc)
		throw runtime_error(mrpt::format(
		    "its uncompressed CRC 0x%08x does not match its records' "
		    "(0x%08x): damaged",
		    c.crc, crc32Of(bytes_ + c.data, c.dataLen)));
	return {map_, bytes_ + c.data, static_cast<size_t>(c.dataLen)};
}

bool McapFile::walkChunk(size_t k, const BagBytes& bytes,
                         const MessageFn& message)
{
	const Chunk& ch = chunks_[k];
	uint64_t pos = 0;
	const uint64_t n = bytes.size;
	while (pos < n)
	{
		const std::string where = "the chunk at byte " +
		                          std::to_string(ch.pos) +
		                          ", in its records: " + at(pos);
		if (n - pos < 9)
		{
			setDamage(ch.pos, where + ": they end inside its opcode and length",
			          true);
			return false;
		}
		const uint8_t op = bytes.data[pos];
		uint64_t len = 0;
		for (int j = 8; j-- > 0;) len = len << 8 | bytes.data[pos + 1 + j];
		if (len > n - pos - 9)
		{
			setDamage(ch.pos,
			          where + mrpt::format(
			                      ": it declares %llu bytes, %llu follow",
			                      static_cast<unsigned long long>(len),
			                      static_cast<unsigned long long>(n - pos - 9)),
			          true);
			return false;
		}
		try
		{
			if (op == kSchema || op == kChannel || op == kMessage)
				record(op, bytes.data + pos + 9, len, static_cast<uint32_t>(k),
				       pos + 9, &message);
		}
		catch (const std::exception& e)
		{
			setDamage(ch.pos, where + ": " + e.what(), true);
			return false;
		}
		pos += 9 + len;
	}
	return true;
}

void McapFile::scan(const MessageFn& message)
{
	// compressed chunks decompressed (and their CRCs checked) up to kAhead
	// ahead, on threads of their own (a file's chunks are independent)
	struct Ready
	{
		BagBytes bytes;
		std::string error;
	};
	constexpr size_t kAhead = 2;
	std::deque<std::future<Ready>> ahead;
	size_t next = 0;  // the next item to start
	auto start = [&](size_t upTo)
	{
		for (; next < items_.size() && next <= upTo; next++)
		{
			if (items_[next].op != kChunk) continue;
			const uint32_t k = items_[next].chunk;
			ahead.push_back(std::async(chunks_[k].compression.empty()
			                               ? std::launch::deferred
			                               : std::launch::async,
			                           [this, k]
			                           {
				                           Ready r;
				                           try
				                           {
					                           r.bytes = chunkBytes(k);
				                           }
				                           catch (const std::exception& e)
				                           {
					                           r.error = e.what();
				                           }
				                           return r;
			                           }));
		}
	};
	for (size_t i = 0; i < items_.size(); i++)
	{
		const Item& it = items_[i];
		if (it.op == kMessage)
		{
			try
			{
				record(kMessage, bytes_ + it.content, it.len, kNoChunk,
				       it.content, &message);
			}
			catch (const std::exception& e)
			{
				setDamage(it.pos, at(it.pos) + ": " + e.what(), true);
				return;
			}
			continue;
		}
		start(i + kAhead);
		Ready r = ahead.front().get();
		ahead.pop_front();
		if (!r.error.empty())
		{
			setDamage(
			    it.pos,
			    "the chunk at byte " + std::to_string(it.pos) + ": " + r.error,
			    true);
			return;  // (the futures left are waited for as they go)
		}
		if (!chunks_[it.chunk].compression.empty())
			cache_.keep(it.chunk, std::static_pointer_cast<const ChunkData>(
			                          r.bytes.owner));
		if (!walkChunk(it.chunk, r.bytes, message)) return;
	}
}

BagBytes McapFile::message(const BagMessageRef& m)
{
	if (m.chunk == kNoChunk) return {map_, bytes_ + m.offset, m.size};
	const Chunk& c = chunks_.at(m.chunk);
	if (c.compression.empty())
		return {map_, bytes_ + c.data + m.offset, m.size};
	const Buffer b = cache_.get(m.chunk, c.pos, [&] { return decompress(c); });
	if (m.offset + m.size > b->size())
		throw runtime_error("a message beyond its chunk");  // (not reached)
	return {b, b->data() + m.offset, m.size};
}

}  // namespace bims::bag
