#include "bag_file.h"

#include "mapped_file.h"

#include <bzlib.h>
#include <fcntl.h>
#include <roslz4/lz4s.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <deque>
#include <future>
#include <stdexcept>

namespace bims::bag
{
namespace
{
using std::runtime_error;

constexpr uint64_t kMaxHeader = 1 << 20;           // a few fields in practice
constexpr uint64_t kMaxChunk = uint64_t{1} << 30;  // 768 kB by default

enum Op : uint8_t
{
	kMessage = 0x02,
	kBagHeader = 0x03,
	kIndex = 0x04,
	kChunk = 0x05,
	kChunkInfo = 0x06,
	kConnection = 0x07
};

std::string at(uint64_t pos)
{
	return "the record at byte " + std::to_string(pos);
}

uint32_t u32(const uint8_t* p)
{
	return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 |
	       uint32_t(p[3]) << 24;
}

/** A record's header fields, name to value bytes. */
using Fields = std::map<std::string, std::string>;

Fields parseFields(const uint8_t* h, uint64_t n, uint64_t pos)
{
	Fields f;
	uint64_t i = 0;
	while (i < n)
	{
		if (n - i < 4)
			throw runtime_error(at(pos) +
			                    ": its header ends inside a field length");
		const uint32_t len = u32(h + i);
		i += 4;
		if (len > n - i)
			throw runtime_error(
			    at(pos) + ": a header field declares " + std::to_string(len) +
			    " bytes, the header has " + std::to_string(n - i) + " left");
		const std::string field(reinterpret_cast<const char*>(h + i), len);
		i += len;
		const size_t eq = field.find('=');
		if (eq == std::string::npos)
			throw runtime_error(at(pos) + ": a header field without '='");
		f[field.substr(0, eq)] = field.substr(eq + 1);
	}
	return f;
}

/** A little-endian unsigned field of \a bytes bytes (absent: false). */
bool number(const Fields& f, const char* name, size_t bytes, uint64_t pos,
            uint64_t& v)
{
	const auto it = f.find(name);
	if (it == f.end()) return false;
	if (it->second.size() != bytes)
		throw runtime_error(at(pos) + ": its field '" + name + "' has " +
		                    std::to_string(it->second.size()) + " bytes, not " +
		                    std::to_string(bytes));
	v = 0;
	for (size_t k = bytes; k-- > 0;)
		v = v << 8 | static_cast<uint8_t>(it->second[k]);
	return true;
}

uint64_t required(const Fields& f, const char* name, size_t bytes, uint64_t pos,
                  const char* record)
{
	uint64_t v = 0;
	if (!number(f, name, bytes, pos, v))
		throw runtime_error(at(pos) + ": " + record + " without its field '" +
		                    name + "'");
	return v;
}

}  // namespace

struct detail::BagRecord
{
	uint8_t op = 0;
	Fields fields;
	uint64_t data = 0, dataLen = 0, end = 0;
	bool cut = false;  ///< its data runs past the bytes there are
};

namespace
{
using Record = detail::BagRecord;

/** The record at \a pos of \a bytes, which must end by \a limit (its data
 * may run past it when \a mayBeCut: then cut, clipped to \a limit). */
Record record(const uint8_t* bytes, uint64_t pos, uint64_t limit,
              bool mayBeCut = false)
{
	Record r;
	if (limit - pos < 4)
		throw runtime_error(at(pos) + " ends inside its header length");
	const uint64_t hl = u32(bytes + pos);
	if (hl > limit - pos - 4 || hl > kMaxHeader)
		throw runtime_error(at(pos) + ": its header declares " +
		                    std::to_string(hl) + " bytes, " +
		                    std::to_string(limit - pos - 4) + " follow");
	r.fields = parseFields(bytes + pos + 4, hl, pos);
	const auto op = r.fields.find("op");
	if (op == r.fields.end() || op->second.size() != 1)
		throw runtime_error(at(pos) + ": no one-byte 'op' field");
	r.op = static_cast<uint8_t>(op->second[0]);
	const uint64_t dl = pos + 4 + hl;
	if (limit - dl < 4)
		throw runtime_error(at(pos) + " ends inside its data length");
	r.dataLen = u32(bytes + dl);
	r.data = dl + 4;
	if (r.dataLen > limit - r.data)
	{
		if (!mayBeCut)
			throw runtime_error(at(pos) + ": its data declares " +
			                    std::to_string(r.dataLen) + " bytes, " +
			                    std::to_string(limit - r.data) + " follow");
		r.cut = true;
		r.dataLen = limit - r.data;
	}
	r.end = r.data + r.dataLen;
	return r;
}

const char* bz2Error(int e)
{
	switch (e)
	{
		case BZ_OUTBUFF_FULL:
			return "it holds more than its declared size";
		case BZ_DATA_ERROR:
		case BZ_DATA_ERROR_MAGIC:
			return "corrupt";
		case BZ_UNEXPECTED_EOF:
			return "it ends early";
		case BZ_MEM_ERROR:
			return "out of memory";
		default:
			return "libbz2 failed";
	}
}
}  // namespace

BagFile::BagFile(const std::string& path, size_t cacheBytes)
    : cache_(cacheBytes)
{
	const MappedFile f = mapFile(path);
	map_ = f.owner;
	bytes_ = f.bytes;
	size_ = f.size;

	// the version line: "#ROSBAG V<major>.<minor>\n"
	// (an empty file maps nothing: fuzz finding ub-empty-bag-memchr)
	const auto* nl = size_ == 0
	                     ? nullptr
	                     : static_cast<const uint8_t*>(std::memchr(
	                           bytes_, '\n', std::min<uint64_t>(size_, 64)));
	const std::string line =
	    nl ? std::string(reinterpret_cast<const char*>(bytes_),
	                     static_cast<size_t>(nl - bytes_))
	       : std::string();
	int major = 0, minor = 0;
	char end = 0;
	if (std::sscanf(line.c_str(), "#ROSBAG V%d.%d%c", &major, &minor, &end) !=
	    2)
		throw runtime_error(
		    "not a readable ROS 1 bag (it does not start with '#ROSBAG "
		    "V2.0'), nor a ROS 2 one (MCAP's magic, sqlite3's header)");
	if (major != 2 || minor != 0)
		throw runtime_error("bag format " + std::to_string(major) + "." +
		                    std::to_string(minor) +
		                    " (its first line): only 2.0, ROS's since 2010, "
		                    "is read");
	walk(static_cast<uint64_t>(nl - bytes_) + 1);
}

BagFile::~BagFile() = default;

void BagFile::setDamage(uint64_t pos, const std::string& what)
{
	if (!damage_.empty() && pos >= damagePos_) return;  // the first
	damage_ = what;
	damagePos_ = pos;
}

void BagFile::walk(uint64_t start)
{
	uint64_t pos = start;
	bool first = true;
	std::map<uint32_t, std::string> indexTopicOf;  // id: topic
	for (; pos < size_; first = false)
	{
		Record r;
		try
		{
			r = record(bytes_, pos, size_, true);
			if (first && r.op != kBagHeader)
				throw runtime_error(at(pos) + " is not the bag header record");
			if (r.cut &&
			    (r.op != kChunk || r.fields.count("compression") == 0 ||
			     r.fields.at("compression") != "none"))
				record(bytes_, pos, size_);  // throws what is cut
			walkRecord(r, pos, first, indexTopicOf);
		}
		catch (const runtime_error& e)
		{
			if (first) throw;
			setDamage(pos, e.what());
			break;
		}
		pos = r.end;
	}
	// damage at or after the index, every chunk the bag header counts
	// before it: only the index is lost, which is not read for messages
	damageLoses_ =
	    !damage_.empty() && !(indexPos_ > 0 && damagePos_ >= indexPos_ &&
	                          chunks_.size() == declaredChunks_);
	const bool indexWhole = damage_.empty() && indexPos_ > 0 &&
	                        chunkInfos_ == chunks_.size() &&
	                        chunkInfos_ == declaredChunks_ &&
	                        indexTopicOf.size() == declaredConnections_;
	if (indexWhole) indexFrom(indexTopicOf);
}

void BagFile::walkRecord(const detail::BagRecord& r, uint64_t pos, bool first,
                         std::map<uint32_t, std::string>& indexTopicOf)
{
	switch (r.op)
	{
		case kBagHeader:
			if (!first) throw runtime_error(at(pos) + ": a second bag header");
			number(r.fields, "index_pos", 8, pos, indexPos_);
			number(r.fields, "conn_count", 4, pos, declaredConnections_);
			number(r.fields, "chunk_count", 4, pos, declaredChunks_);
			break;
		case kChunk:
			addChunk(r, pos);
			break;
		case kConnection:
		{
			const uint32_t id = addConnection(r, bytes_, pos);
			indexTopicOf[id] = r.fields.at("topic");
			break;
		}
		case kChunkInfo:
		{
			const uint64_t count =
			    required(r.fields, "count", 4, pos, "a chunk info");
			if (count * 8 > r.dataLen)
				throw runtime_error(at(pos) + ": " + std::to_string(count) +
				                    " index entries of 8 bytes in " +
				                    std::to_string(r.dataLen));
			for (uint64_t k = 0; k < count; k++)
				indexCounts_[u32(bytes_ + r.data + 8 * k)] +=
				    u32(bytes_ + r.data + 8 * k + 4);
			chunkInfos_++;
			break;
		}
		case kIndex:
		case kMessage:
			break;  // the messages are read from their chunks
		default:
			throw runtime_error(at(pos) + ": a record of op " +
			                    std::to_string(r.op) + ", none of a bag's");
	}
}

void BagFile::indexFrom(const std::map<uint32_t, std::string>& indexTopicOf)
{
	std::map<std::string, BagTopicInfo> topics;
	for (const auto& [id, topic] : indexTopicOf)
	{
		auto& t = topics[topic];
		t.name = topic;
		t.type = connections_[connectionIds_.at(id)].type;
		t.messages += indexCounts_[id];
	}
	for (auto& [name, t] : topics) index_.push_back(t);
}

void BagFile::addChunk(const detail::BagRecord& r, uint64_t pos)
{
	const auto c = r.fields.find("compression");
	if (c == r.fields.end())
		throw runtime_error(at(pos) + ": a chunk without its compression");
	Chunk k;
	k.pos = pos;
	k.data = r.data;
	k.dataLen = r.dataLen;
	k.size = required(r.fields, "size", 4, pos, "a chunk");
	if (k.size > kMaxChunk)
		throw runtime_error(at(pos) + ": a chunk of " + std::to_string(k.size) +
		                    " bytes uncompressed, beyond 1 GiB");
	if (c->second == "bz2")
		k.kind = Chunk::Bz2;
	else if (c->second == "lz4")
		k.kind = Chunk::Lz4;
	else if (c->second != "none")
		throw runtime_error(at(pos) + ": a chunk compressed with '" +
		                    c->second + "' (a bag's are none, bz2, lz4)");
	if (k.kind == Chunk::None && !r.cut && k.size != r.dataLen)
		throw runtime_error(at(pos) + ": an uncompressed chunk of " +
		                    std::to_string(r.dataLen) + " bytes declaring " +
		                    std::to_string(k.size));
	k.cut = r.cut;
	chunks_.push_back(k);
}

uint32_t BagFile::addConnection(const detail::BagRecord& r,
                                const uint8_t* bytes, uint64_t pos)
{
	const auto id = static_cast<uint32_t>(
	    required(r.fields, "conn", 4, pos, "a connection"));
	const auto topic = r.fields.find("topic");
	if (topic == r.fields.end())
		throw runtime_error(at(pos) + ": a connection without a topic");
	if (connectionIds_.count(id)) return id;  // (again, in the index)
	const Fields f = parseFields(bytes + r.data, r.dataLen, pos);
	BagConnection c;
	c.topic = topic->second;
	const auto type = f.find("type"), md5 = f.find("md5sum");
	if (type == f.end() || md5 == f.end())
		throw runtime_error(at(pos) +
		                    ": a connection without its type and md5sum");
	c.type = type->second;
	c.md5 = md5->second;
	connectionIds_[id] = static_cast<uint32_t>(connections_.size());
	connections_.push_back(c);
	return id;
}

std::vector<BagTopicInfo> BagFile::indexTopics() const
{
	return index_;
}

BagFile::Buffer BagFile::decompress(const Chunk& c) const
{
	auto out = std::make_shared<ChunkData>();
	out->n = static_cast<size_t>(c.size);
	out->bytes.reset(new uint8_t[out->n]);  // (not zeroed)
	if (c.size == 0) return out;
	auto* dst = reinterpret_cast<char*>(out->bytes.get());
	// (both libraries take the input as not const; neither writes it)
	auto* src =
	    const_cast<char*>(reinterpret_cast<const char*>(bytes_ + c.data));
	const auto srcLen = static_cast<unsigned>(c.dataLen);
	unsigned n = static_cast<unsigned>(c.size);
	if (c.kind == Chunk::Bz2)
	{
		const int e = BZ2_bzBuffToBuffDecompress(dst, &n, src, srcLen, 0, 0);
		if (e != BZ_OK)
			throw runtime_error(std::string("its bz2 data cannot be "
			                                "decompressed: ") +
			                    bz2Error(e));
	}
	else
	{
		const int e = roslz4_buffToBuffDecompress(src, srcLen, dst, &n);
		if (e != ROSLZ4_OK)
			throw runtime_error(
			    std::string("its lz4 data cannot be decompressed: ") +
			    (e == ROSLZ4_OUTPUT_SMALL ? "it holds more than its declared "
			                                "size"
			                              : "corrupt"));
	}
	if (n != c.size)
		throw runtime_error("it decompresses to " + std::to_string(n) +
		                    " bytes, not its declared " +
		                    std::to_string(c.size));
	return out;
}

BagBytes BagFile::chunkBytes(size_t k) const
{
	const Chunk& c = chunks_[k];
	if (c.kind == Chunk::None)
		return {map_, bytes_ + c.data, static_cast<size_t>(c.dataLen)};
	Buffer b = decompress(c);
	return {b, b->data(), b->size()};
}

bool BagFile::walkChunk(size_t k, const BagBytes& bytes,
                        const MessageFn& message)
{
	const Chunk& c = chunks_[k];
	auto damaged = [&](const std::string& what)
	{
		setDamage(c.pos, "the chunk at byte " + std::to_string(c.pos) +
		                     ", in its data: " + what);
		damageLoses_ = true;
		return false;
	};
	for (uint64_t p = 0; p < bytes.size;)
	{
		Record m;
		BagMessageRef ref;
		try
		{
			m = record(bytes.data, p, bytes.size);
			if (m.op == kConnection)
			{
				addConnection(m, bytes.data, p);
				p = m.end;
				continue;
			}
			if (m.op != kMessage)
				throw runtime_error(at(p) + ": a record of op " +
				                    std::to_string(m.op) + " inside a chunk");
			const auto id = static_cast<uint32_t>(
			    required(m.fields, "conn", 4, p, "a message"));
			const auto it = connectionIds_.find(id);
			if (it == connectionIds_.end())
				throw runtime_error(at(p) + ": a message of connection " +
				                    std::to_string(id) +
				                    ", which no record declares before it");
			const uint64_t t = required(m.fields, "time", 8, p, "a message");
			ref.connection = it->second;
			ref.time = (t & 0xffffffffu) * 1000000000ull + (t >> 32);
			ref.chunk = static_cast<uint32_t>(k);
			ref.offset = m.data;
			ref.size = static_cast<uint32_t>(m.dataLen);
		}
		catch (const runtime_error& e)
		{
			return damaged(e.what());
		}
		message(ref, bytes.data + m.data);
		p = m.end;
	}
	if (c.cut)
		return damaged("cut short after its " + std::to_string(c.dataLen) +
		               " of " + std::to_string(c.size) + " bytes");
	return true;
}

void BagFile::scan(const MessageFn& message)
{
	struct Ready
	{
		BagBytes bytes;
		std::string error;
	};
	// compressed chunks decompressed up to kAhead ahead, on threads of
	// their own (a bag's chunks are independent)
	constexpr size_t kAhead = 2;
	std::deque<std::future<Ready>> ahead;
	size_t next = 0;
	for (size_t k = 0; k < chunks_.size(); k++)
	{
		for (; next < chunks_.size() && next <= k + kAhead; next++)
		{
			const bool compressed = chunks_[next].kind != Chunk::None;
			ahead.push_back(std::async(
			    compressed ? std::launch::async : std::launch::deferred,
			    [this, n = next]
			    {
				    Ready r;
				    try
				    {
					    r.bytes = chunkBytes(n);
				    }
				    catch (const std::exception& e)
				    {
					    r.error = e.what();
				    }
				    return r;
			    }));
		}
		Ready r = ahead.front().get();
		ahead.pop_front();
		if (!r.error.empty())
		{
			setDamage(chunks_[k].pos, "the chunk at byte " +
			                              std::to_string(chunks_[k].pos) +
			                              ": " + r.error);
			damageLoses_ = true;
			break;
		}
		// BZ2 chunks kept for message(): decompressing one again costs ~30
		// times reading it back; an LZ4 chunk decompresses about as fast as
		// the fresh memory to keep it takes to fault in (docs/import-bag.md)
		if (chunks_[k].kind == Chunk::Bz2)
			cache_.keep(
			    static_cast<uint32_t>(k),
			    std::static_pointer_cast<const ChunkData>(r.bytes.owner));
		if (!walkChunk(k, r.bytes, message)) break;
	}
}

BagBytes BagFile::message(const BagMessageRef& m)
{
	const Chunk& c = chunks_.at(m.chunk);
	if (c.kind == Chunk::None)
		return {map_, bytes_ + c.data + m.offset, m.size};
	const Buffer b = cache_.get(m.chunk, c.pos, [&] { return decompress(c); });
	if (m.offset + m.size > b->size())
		throw runtime_error("a message beyond its chunk");  // (not reached)
	return {b, b->data() + m.offset, m.size};
}

}  // namespace bims::bag
