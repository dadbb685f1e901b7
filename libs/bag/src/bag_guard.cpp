#include "bag_guard.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

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

/** A record's header fields, name to value bytes. */
using Fields = std::map<std::string, std::string>;

Fields parseFields(const std::string& h, uint64_t pos)
{
	Fields f;
	size_t i = 0;
	while (i < h.size())
	{
		if (h.size() - i < 4)
			throw runtime_error(at(pos) +
			                    ": its header ends inside a field "
			                    "length");
		uint32_t len = 0;
		std::memcpy(&len, h.data() + i, 4);
		i += 4;
		if (len > h.size() - i)
			throw runtime_error(at(pos) + ": a header field declares " +
			                    std::to_string(len) +
			                    " bytes, the header has " +
			                    std::to_string(h.size() - i) + " left");
		const std::string field = h.substr(i, len);
		i += len;
		const size_t eq = field.find('=');
		if (eq == std::string::npos)
			throw runtime_error(at(pos) + ": a header field without '='");
		f[field.substr(0, eq)] = field.substr(eq + 1);
	}
	return f;
}

/** A little-endian unsigned field of \a bytes bytes (absent: none). */
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

class Walker
{
 public:
	/** The records of \a path from byte \a start (after the version
	 * line). */
	Walker(const std::string& path, uint64_t start)
	    : f_(path, std::ios::binary), start_(start)
	{
		f_.seekg(0, std::ios::end);
		size_ = static_cast<uint64_t>(f_.tellg());
	}

	void walk()
	{
		uint64_t pos = start_;
		uint64_t indexPos = 0, connections = 0, chunks = 0;
		bool first = true;
		size_t connectionsAfter = 0, chunkInfosAfter = 0;
		while (pos < size_)
		{
			const Record r = record(pos, size_);
			if (first && r.op != kBagHeader)
				throw runtime_error(at(pos) + " is not the bag header record");
			if (r.op == kBagHeader)
			{
				if (!first)
					throw runtime_error(at(pos) + ": a second bag header");
				number(r.fields, "index_pos", 8, pos, indexPos);
				number(r.fields, "conn_count", 4, pos, connections);
				number(r.fields, "chunk_count", 4, pos, chunks);
				if (indexPos > size_)
					throw runtime_error("the bag header's index position " +
					                    std::to_string(indexPos) +
					                    " is beyond the file's " +
					                    std::to_string(size_) + " bytes");
			}
			first = false;
			if (indexPos > 0 && pos >= indexPos)
			{
				connectionsAfter += r.op == kConnection;
				chunkInfosAfter += r.op == kChunkInfo;
			}
			if (r.op == kChunk) chunk(r, pos);
			if (r.op == kIndex || r.op == kChunkInfo) entries(r, pos);
			pos = r.end;
		}
		if (indexPos > 0 &&
		    (connections > connectionsAfter || chunks > chunkInfosAfter))
			throw runtime_error(
			    "the bag header declares " + std::to_string(connections) +
			    " connections and " + std::to_string(chunks) +
			    " chunks, its index holds " + std::to_string(connectionsAfter) +
			    " and " + std::to_string(chunkInfosAfter));
	}

 private:
	struct Record
	{
		uint8_t op = 0;
		Fields fields;
		uint64_t data = 0, dataLen = 0, end = 0;
	};

	uint32_t u32(uint64_t pos)
	{
		uint8_t b[4];
		f_.seekg(static_cast<std::streamoff>(pos));
		if (!f_.read(reinterpret_cast<char*>(b), 4))
			throw runtime_error("cannot read byte " + std::to_string(pos));
		return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 |
		       uint32_t(b[3]) << 24;
	}

	/** The record at \a pos, which must end by \a limit. */
	Record record(uint64_t pos, uint64_t limit)
	{
		Record r;
		if (limit - pos < 4)
			throw runtime_error(at(pos) + " ends inside its header length");
		const uint64_t hl = u32(pos);
		if (hl > limit - pos - 4 || hl > kMaxHeader)
			throw runtime_error(at(pos) + ": its header declares " +
			                    std::to_string(hl) + " bytes, " +
			                    std::to_string(limit - pos - 4) + " follow");
		std::string h(hl, '\0');
		f_.seekg(static_cast<std::streamoff>(pos + 4));
		if (!f_.read(h.data(), static_cast<std::streamsize>(hl)))
			throw runtime_error(at(pos) + ": its header cannot be read");
		r.fields = parseFields(h, pos);
		const auto op = r.fields.find("op");
		if (op == r.fields.end() || op->second.size() != 1)
			throw runtime_error(at(pos) + ": no one-byte 'op' field");
		r.op = static_cast<uint8_t>(op->second[0]);
		const uint64_t dl = pos + 4 + hl;
		if (limit - dl < 4)
			throw runtime_error(at(pos) + " ends inside its data length");
		r.dataLen = u32(dl);
		r.data = dl + 4;
		if (r.dataLen > limit - r.data)
			throw runtime_error(at(pos) + ": its data declares " +
			                    std::to_string(r.dataLen) + " bytes, " +
			                    std::to_string(limit - r.data) + " follow");
		r.end = r.data + r.dataLen;
		return r;
	}

	void chunk(const Record& r, uint64_t pos)
	{
		const auto c = r.fields.find("compression");
		uint64_t size = 0;
		if (c == r.fields.end() || !number(r.fields, "size", 4, pos, size))
			throw runtime_error(at(pos) +
			                    ": a chunk without compression and size");
		if (size > kMaxChunk)
			throw runtime_error(at(pos) + ": a chunk of " +
			                    std::to_string(size) +
			                    " bytes uncompressed, beyond 1 GiB");
		chunkSize_ = size;
		messageStarts_.clear();
		walkedChunk_ = c->second == "none";
		if (!walkedChunk_) return;  // (its records: not walked)
		if (size != r.dataLen)
			throw runtime_error(at(pos) + ": an uncompressed chunk of " +
			                    std::to_string(r.dataLen) +
			                    " bytes declaring " + std::to_string(size));
		for (uint64_t p = r.data; p < r.end;)
		{
			const Record m = record(p, r.end);
			if (m.op != kMessage && m.op != kConnection)
				throw runtime_error(at(p) + ": a record of op " +
				                    std::to_string(m.op) + " inside a chunk");
			if (m.op == kMessage) messageStarts_.insert(p - r.data);
			p = m.end;
		}
	}

	/** An index record's entries must be within its data. */
	void entries(const Record& r, uint64_t pos)
	{
		uint64_t count = 0;
		if (!number(r.fields, "count", 4, pos, count)) return;
		const uint64_t each = r.op == kIndex ? 12 : 8;
		if (count * each > r.dataLen)
			throw runtime_error(at(pos) + ": " + std::to_string(count) +
			                    " index entries of " + std::to_string(each) +
			                    " bytes in " + std::to_string(r.dataLen));
		if (r.op != kIndex) return;
		// the chunk's messages these entries point at: rosbag reads a
		// record header at each offset in the chunk, unchecked
		for (uint64_t k = 0; k < count; k++)
		{
			const uint64_t offset = u32(r.data + k * each + 8);
			const bool within = offset + 8 <= chunkSize_;
			if (!within || (walkedChunk_ && !messageStarts_.count(offset)))
				throw runtime_error(
				    at(pos) + ": index entry " + std::to_string(k) +
				    " points at byte " + std::to_string(offset) +
				    " of its chunk, " +
				    (within ? std::string("not the start of a message there")
				            : "beyond its " + std::to_string(chunkSize_) +
				                  " bytes"));
		}
	}

	std::ifstream f_;
	uint64_t start_ = 0, size_ = 0;
	/** The last chunk read: its uncompressed size and, when it was walked
	 * (uncompressed), where its messages start (from its data). */
	uint64_t chunkSize_ = 0;
	bool walkedChunk_ = false;
	std::set<uint64_t> messageStarts_;
};
}  // namespace

void checkBagRecords(const std::string& path)
{
	// the version line as rosbag reads it: any "#ROS<word> V<major>.<minor>"
	// up to the first newline (fuzz finding asan-version-line-header-field:
	// "#ROSBAF V2.0" was read as a bag, and its header past its end)
	std::string line;
	{
		std::ifstream f(path, std::ios::binary);
		std::getline(f, line);
		if (!f) return;  // no newline: rosbag refuses it
	}
	char word[100];
	int major = 0, minor = 0;
	if (std::sscanf(line.c_str(), "#ROS%99s V%d.%d", word, &major, &minor) != 3)
		return;  // rosbag refuses it
	if (major != 2 || minor != 0)
		throw runtime_error("bag format " + std::to_string(major) + "." +
		                    std::to_string(minor) +
		                    " (its first line): only 2.0, ROS's since 2010, "
		                    "is read");
	Walker(path, line.size() + 1).walk();
}

namespace
{
/** Reads a serialized ROS message's fields in order, each length checked
 * against the bytes left. */
class Cursor
{
 public:
	Cursor(const uint8_t* p, size_t n) : p_(p), n_(n) {}
	void skip(uint64_t k, const char* what)
	{
		if (k > n_ - i_)
			throw runtime_error("its " + std::string(what) + " declares " +
			                    std::to_string(k) + " bytes, the message has " +
			                    std::to_string(n_ - i_) + " left: corrupt");
		i_ += static_cast<size_t>(k);
	}
	uint32_t u32(const char* what)
	{
		if (n_ - i_ < 4)
			throw runtime_error("the message ends inside its " +
			                    std::string(what) + ": corrupt");
		uint32_t v = 0;
		std::memcpy(&v, p_ + i_, 4);
		i_ += 4;
		return v;
	}
	/** A string or array of \a elem-byte elements. */
	void array(uint64_t elem, const char* what)
	{
		skip(u32(what) * elem, what);
	}
	void header()
	{
		skip(12, "header");  // seq, stamp
		array(1, "header's frame_id");
	}

 private:
	const uint8_t* p_;
	size_t n_, i_ = 0;
};
}  // namespace

void checkMessageArrays(const uint8_t* bytes, size_t n, ArrayMessage kind)
{
	Cursor c(bytes, n);
	c.header();
	switch (kind)
	{
		case ArrayMessage::Image:
			c.skip(8, "height and width");
			c.array(1, "encoding");
			c.skip(5, "is_bigendian and step");
			c.array(1, "data");
			break;
		case ArrayMessage::CompressedImage:
			c.array(1, "format");
			c.array(1, "data");
			break;
		case ArrayMessage::CameraInfo:
			c.skip(8, "height and width");
			c.array(1, "distortion_model");
			c.array(8, "D");
			break;
	}
}

}  // namespace bims::bag
