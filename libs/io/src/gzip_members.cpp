#include <bims/io/gzip_members.h>

#include <libdeflate.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>

namespace bims
{
namespace
{
// The member's header: ID1 ID2 CM FLG MTIME(4) XFL OS, then FEXTRA: XLEN(2)
// and one subfield SI1 SI2 LEN(2) with the member's size and its data's
// size, 64 bits each, little-endian.
constexpr uint8_t kFlagExtra = 4;
constexpr uint8_t kOsUnix = 3;
constexpr uint8_t kSubfieldId[2] = {'B', 'm'};
constexpr size_t kSubfieldBytes = 16;
constexpr size_t kExtraBytes = 4 + kSubfieldBytes;
constexpr size_t kHeaderBytes = 10 + 2 + kExtraBytes;
constexpr size_t kTrailerBytes = 8;

void putLE(uint8_t* p, uint64_t v, int bytes)
{
	for (int i = 0; i < bytes; i++) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
uint64_t getLE(const uint8_t* p, int bytes)
{
	uint64_t v = 0;
	for (int i = bytes - 1; i >= 0; i--) v = (v << 8) | p[i];
	return v;
}

struct Compressor
{
	explicit Compressor(int level) : c(libdeflate_alloc_compressor(level))
	{
		if (!c) throw std::runtime_error("libdeflate: cannot compress");
	}
	~Compressor() { libdeflate_free_compressor(c); }
	Compressor(const Compressor&) = delete;
	Compressor& operator=(const Compressor&) = delete;
	libdeflate_compressor* c;
};

std::vector<uint8_t> member(Compressor& z, int level, const uint8_t* data,
                            size_t n)
{
	std::vector<uint8_t> out(kHeaderBytes +
	                         libdeflate_deflate_compress_bound(z.c, n) +
	                         kTrailerBytes);
	const size_t deflated = libdeflate_deflate_compress(
	    z.c, data, n, out.data() + kHeaderBytes, out.size() - kHeaderBytes);
	if (deflated == 0 && n > 0)
		throw std::runtime_error("libdeflate: compression failed");
	out.resize(kHeaderBytes + deflated + kTrailerBytes);
	uint8_t* h = out.data();
	h[0] = 0x1f;
	h[1] = 0x8b;
	h[2] = 8;  // deflate
	h[3] = kFlagExtra;
	putLE(h + 4, 0, 4);  // no time stamp: the same bytes for the same data
	h[8] = level == 9 ? 2 : level == 1 ? 4 : 0;  // XFL as zlib sets it
	h[9] = kOsUnix;
	putLE(h + 10, kExtraBytes, 2);
	h[12] = kSubfieldId[0];
	h[13] = kSubfieldId[1];
	putLE(h + 14, kSubfieldBytes, 2);
	putLE(h + 16, out.size(), 8);
	putLE(h + 24, n, 8);
	uint8_t* t = out.data() + kHeaderBytes + deflated;
	putLE(t, libdeflate_crc32(0, data, n), 4);
	putLE(t + 4, n & 0xffffffffu, 4);
	return out;
}
}  // namespace

std::vector<uint8_t> gzipMember(const void* data, size_t n, int level)
{
	Compressor z(level);
	return member(z, level, static_cast<const uint8_t*>(data), n);
}

GzipMemberWriter::GzipMemberWriter(std::string path, int level, int threads,
                                   size_t memberBytes)
    : file_(std::move(path)),
      level_(level),
      memberBytes_(std::max<size_t>(memberBytes, 1)),
      maxInFlight_(size_t(std::max(threads, 1)) + 1)
{
	if (level < 1 || level > 9)
		throw std::invalid_argument(file_.path() +
		                            ": gzip level must be in 1..9");
	current_.reserve(memberBytes_);
	for (int i = 0; i < std::max(threads, 1); i++)
		workers_.emplace_back([this] { work(); });
}

GzipMemberWriter::~GzipMemberWriter()
{
	try
	{
		close();
	}
	catch (...)
	{
	}
}

void GzipMemberWriter::append(const void* data, size_t n)
{
	if (closed_) throw std::runtime_error(path() + ": write after close");
	throwIfFailed();
	const auto* p = static_cast<const uint8_t*>(data);
	current_.insert(current_.end(), p, p + n);
	if (current_.size() >= memberBytes_) submit();
}

void GzipMemberWriter::submit()
{
	std::unique_lock<std::mutex> lock(m_);
	cv_.wait(
	    lock, [&]
	    { return submitted_ - written_ < maxInFlight_ || !error_.empty(); });
	if (!error_.empty()) throw std::runtime_error(error_);
	Job job;
	job.seq = submitted_++;
	job.data.swap(current_);
	jobs_.push_back(std::move(job));
	cv_.notify_all();
	lock.unlock();
	current_.reserve(memberBytes_);
}

void GzipMemberWriter::flush()
{
	if (closed_) return;
	if (!current_.empty()) submit();
	std::unique_lock<std::mutex> lock(m_);
	cv_.wait(lock, [&] { return written_ == submitted_; });
	if (!error_.empty()) throw std::runtime_error(error_);
}

void GzipMemberWriter::throwIfFailed()
{
	const std::lock_guard<std::mutex> lock(m_);
	if (!error_.empty()) throw std::runtime_error(error_);
}

void GzipMemberWriter::work()
{
	std::unique_ptr<Compressor> z;
	for (;;)
	{
		Job job;
		{
			std::unique_lock<std::mutex> lock(m_);
			cv_.wait(lock, [&] { return !jobs_.empty() || stop_; });
			if (jobs_.empty()) return;
			job = std::move(jobs_.front());
			jobs_.pop_front();
		}
		std::vector<uint8_t> out;
		std::string failed;
		try
		{
			if (!z) z = std::make_unique<Compressor>(level_);
			out = member(*z, level_, job.data.data(), job.data.size());
		}
		catch (const std::exception& e)
		{
			failed = path() + ": " + e.what();
		}
		std::vector<uint8_t>().swap(job.data);
		// in order: the member before this one is in the file
		std::unique_lock<std::mutex> lock(m_);
		cv_.wait(lock, [&] { return written_ == job.seq; });
		if (error_.empty() && failed.empty())
		{
			lock.unlock();  // only this worker writes now
			try
			{
				file_.append(out.data(), out.size());
			}
			catch (const std::exception& e)
			{
				failed = e.what();
			}
			lock.lock();
		}
		if (error_.empty()) error_ = failed;
		written_++;
		cv_.notify_all();
	}
}

void GzipMemberWriter::close()
{
	if (closed_) return;
	std::string failed;
	try
	{
		flush();
		if (file_.size() == 0)
		{
			const auto empty = gzipMember(nullptr, 0, level_);
			file_.append(empty.data(), empty.size());
		}
	}
	catch (const std::exception& e)
	{
		failed = e.what();
	}
	closed_ = true;
	{
		const std::lock_guard<std::mutex> lock(m_);
		stop_ = true;
	}
	cv_.notify_all();
	for (auto& w : workers_) w.join();
	workers_.clear();
	try
	{
		file_.close();
	}
	catch (const std::exception& e)
	{
		if (failed.empty()) failed = e.what();
	}
	if (!failed.empty()) throw std::runtime_error(failed);
}

uint64_t gzipDataBytes(const std::string& path)
{
	std::ifstream f(path, std::ios::binary);
	if (!f) return 0;
	f.seekg(0, std::ios::end);
	const auto size = static_cast<uint64_t>(f.tellg());
	uint8_t h[kHeaderBytes] = {};
	f.seekg(0);
	f.read(reinterpret_cast<char*>(h), 2);
	if (!f || h[0] != 0x1f || h[1] != 0x8b || size < 18) return size;
	// the members' own sizes, when each has them
	uint64_t data = 0, at = 0;
	while (at < size)
	{
		f.seekg(static_cast<std::streamoff>(at));
		f.read(reinterpret_cast<char*>(h), kHeaderBytes);
		const uint64_t bytes = getLE(h + 16, 8);
		if (!f || h[0] != 0x1f || h[1] != 0x8b || !(h[3] & kFlagExtra) ||
		    getLE(h + 10, 2) != kExtraBytes || h[12] != kSubfieldId[0] ||
		    h[13] != kSubfieldId[1] || getLE(h + 14, 2) != kSubfieldBytes ||
		    bytes < kHeaderBytes + kTrailerBytes)
			break;
		data += getLE(h + 24, 8);
		at += bytes;
	}
	if (at >= size) return data;
	// another writer's: the trailer's last 4 bytes are the (last member's)
	// data size modulo 2^32
	f.clear();
	f.seekg(-4, std::ios::end);
	f.read(reinterpret_cast<char*>(h), 4);
	if (!f) return size;
	data = getLE(h, 4);
	while (data < size) data += uint64_t(1) << 32;
	return data;
}

}  // namespace bims
