#include <bims/io/output_paths.h>
#include <bims/io/rawlog.h>

#include <bims/io/gzip_members.h>

#include <fstream>

#include <filesystem>

#include <mrpt/img/CImage.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/archiveFrom_std_streams.h>
#include <mrpt/system/filesystem.h>
#include "scan_guard.h"

#include <algorithm>
#include <cstring>

namespace bims
{
namespace
{
/** A CArchive appending to a byte vector. MRPT serializes a matrix element
 * by element: buffering the object in memory makes that one file write per
 * object instead of one per element, and a failed serialization writes
 * nothing. */
class VectorArchive : public mrpt::serialization::CArchive
{
 public:
	explicit VectorArchive(std::vector<uint8_t>& buf) : buf_(buf) {}

 protected:
	size_t write(const void* d, size_t n) override
	{
		const auto* p = static_cast<const uint8_t*>(d);
		if (n == 1)
			buf_.push_back(*p);  // e.g. pixel labels, one byte per call
		else
			buf_.insert(buf_.end(), p, p + n);
		return n;
	}
	size_t read(void*, size_t) override
	{
		throw std::logic_error("VectorArchive is write-only");
	}

 private:
	std::vector<uint8_t>& buf_;
};

/** An allocator whose resize() leaves new bytes uninitialised: the read
 * buffer is filled from the file right after growing (a 640x480 scan is
 * ~2 MB that would otherwise be zeroed first). */
template <typename T>
struct UninitAllocator : std::allocator<T>
{
	template <typename U>
	struct rebind
	{
		using other = UninitAllocator<U>;
	};
	UninitAllocator() = default;
	template <typename U>
	UninitAllocator(const UninitAllocator<U>&) noexcept
	{
	}
	template <typename U>
	void construct(U* p) noexcept
	{
		::new (static_cast<void*>(p)) U;
	}
	template <typename U, typename... Args>
	void construct(U* p, Args&&... args)
	{
		::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
	}
};

/** A CArchive reading a (gzip or plain) file through a buffer of its own,
 * for the same reason: one gzread per 256 KB instead of one per matrix
 * element. */
class BufferedInArchive : public mrpt::serialization::CArchive
{
 public:
	explicit BufferedInArchive(mrpt::io::CFileGZInputStream& in) : in_(in)
	{
		// room for a whole 640x480 scan with RGB and labels (~2 MB), which
		// peek() holds at once: no reallocation while it grows
		buf_.reserve(kPeekReserve);
	}
	/** Bytes handed out so far. */
	uint64_t position() const { return pos_; }
	/** Nothing left, in the buffer or in the file (false on a read error:
	 * that is no clean end). */
	bool atEof()
	{
		if (next_ < buf_.size()) return false;
		if (eof_) return true;
		try
		{
			fill();
		}
		catch (const std::exception&)
		{
			return false;
		}
		return next_ == buf_.size();
	}
	/** The next n bytes without consuming them (fewer at the end of the
	 * file). */
	std::pair<const uint8_t*, size_t> peek(size_t n)
	{
		if (buf_.size() - next_ < n && !eof_)
		{
			buf_.erase(buf_.begin(), buf_.begin() + next_);
			next_ = 0;
			while (buf_.size() < n && !eof_)
			{
				const size_t have = buf_.size();
				buf_.resize(have + std::max(kChunk, n - have));
				const size_t k =
				    in_.Read(buf_.data() + have, buf_.size() - have);
				buf_.resize(have + k);
				if (k == 0) eof_ = true;
			}
		}
		return {buf_.data() + next_, buf_.size() - next_};
	}

 protected:
	size_t write(const void*, size_t) override
	{
		throw std::logic_error("BufferedInArchive is read-only");
	}
	size_t read(void* d, size_t n) override
	{
		auto* out = static_cast<uint8_t*>(d);
		if (n <= buf_.size() - next_)
		{
			// in the buffer: most calls (MRPT reads matrices element by
			// element, pixel labels one byte at a time)
			if (n == 1)
				*out = buf_[next_];
			else
				std::memcpy(out, buf_.data() + next_, n);
			next_ += n;
			pos_ += n;
			return n;
		}
		size_t got = 0;
		while (got < n)
		{
			if (next_ == buf_.size())
			{
				if (eof_) break;
				fill();
				if (next_ == buf_.size()) break;
			}
			const size_t k = std::min(n - got, buf_.size() - next_);
			std::memcpy(out + got, buf_.data() + next_, k);
			next_ += k;
			got += k;
		}
		pos_ += got;
		return got;
	}

 private:
	void fill()
	{
		buf_.resize(kChunk);
		const size_t k = in_.Read(buf_.data(), kChunk);
		buf_.resize(k);
		next_ = 0;
		if (k == 0) eof_ = true;
	}

	static constexpr size_t kChunk = 256 * 1024;
	static constexpr size_t kPeekReserve = 4 * 1024 * 1024;
	mrpt::io::CFileGZInputStream& in_;
	std::vector<uint8_t, UninitAllocator<uint8_t>> buf_;
	size_t next_ = 0;
	uint64_t pos_ = 0;
	bool eof_ = false;
};
}  // namespace

std::string rawlogImagesDirectory(const std::string& rawlogPath)
{
	std::string dir = mrpt::system::extractFileDirectory(rawlogPath);
	if (!dir.empty() && dir.back() != '/') dir += '/';
	return dir + mrpt::system::extractFileName(rawlogPath) + "_Images";
}

void checkRawlogPath(const std::string& path)
{
	namespace fs = std::filesystem;
	std::error_code ec;
	const auto st = fs::status(path, ec);
	if (!fs::exists(st)) throw RawlogError(path + ": no such rawlog file");
	if (fs::is_directory(st))
	{
		const auto has = [&](const char* f)
		{ return fs::exists(fs::path(path) / f, ec); };
		std::string hint;
		if (has("rgb.txt") || has("depth.txt"))
			hint = ": a TUM RGB-D folder; import it first: bims-import-tum " +
			       path + " -o OUT.rawlog -c CONFIG.ini";
		else if (has("odometry.csv"))
			hint =
			    ": a Stray Scanner capture; import it first: "
			    "bims-import-stray " +
			    path + " -o OUT.rawlog -c stray.ini";
		throw RawlogError(path + ": a folder, not a rawlog file" + hint);
	}
	if (!fs::is_regular_file(st))
		throw RawlogError(path + ": not a regular file, not a rawlog");
	if (fs::file_size(path, ec) == 0 && !ec)
		throw RawlogError(path + ": an empty file (0 bytes), not a rawlog");
	if (!std::ifstream(path))
		throw RawlogError(path + ": cannot open rawlog file (permissions?)");
}

RawlogReader::RawlogReader(const std::string& path) : path_(path)
{
	checkRawlogPath(path);
	if (!in_.open(path)) throw RawlogError(path + ": cannot open rawlog file");
	arch_ = std::make_unique<BufferedInArchive>(in_);
	const std::string imgDir = rawlogImagesDirectory(path);
	if (mrpt::system::directoryExists(imgDir))
		mrpt::img::CImage::setImagesPathBase(imgDir);
}

uint64_t RawlogReader::bytesRead() const
{
	return static_cast<const BufferedInArchive&>(*arch_).position();
}

size_t count3DScans(const std::vector<std::string>& rawlogs,
                    const std::string& label, size_t atMost)
{
	size_t n = 0;
	for (const auto& path : rawlogs)
	{
		RawlogReader r(path);
		while (n < atMost)
		{
			const auto o = r.next();
			if (!o) break;
			if (auto s = std::dynamic_pointer_cast<
			        mrpt::obs::CObservation3DRangeScan>(o);
			    s && (label.empty() || s->sensorLabel == label))
				++n;
		}
	}
	return n;
}

uint64_t rawlogDataBytes(const std::string& path)
{
	return gzipDataBytes(path);  // a plain file's size too
}

mrpt::obs::CObservation::Ptr RawlogReader::next()
{
	while (pending_.empty())
	{
		if (atEnd_) return nullptr;
		mrpt::serialization::CSerializable::Ptr obj;
		auto& arch = static_cast<BufferedInArchive&>(*arch_);
		const uint64_t pos0 = arch.position();
		bool cut = false;
		const std::string bad = checkSerializedSizes(
		    [&arch](size_t n) { return arch.peek(n); }, &cut);
		if (!bad.empty())
			throw RawlogError(path_ +
			                  (cut ? ": truncated or corrupt rawlog at entry "
			                       : ": corrupt rawlog at entry ") +
			                  std::to_string(entry_ + 1) + " (" +
			                  std::to_string(nObs_) +
			                  " observations read before): " + bad);
		try
		{
			obj = arch_->ReadObject();
			++entry_;
		}
		catch (const std::exception& e)
		{
			// EOF before the first byte of an object is the clean end.
			if (arch.position() == pos0 && arch.atEof())
			{
				atEnd_ = true;
				return nullptr;
			}
			++entry_;
			std::string what = e.what();
			if (what.size() > 300) what = what.substr(0, 300) + "...";
			throw RawlogError(
			    path_ + ": truncated or corrupt rawlog at entry " +
			    std::to_string(entry_) + " (" + std::to_string(nObs_) +
			    " observations read before): " + what);
		}
		if (!obj)
			throw RawlogError(path_ + ": null object at entry " +
			                  std::to_string(entry_));
		if (auto o = std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj))
			pending_.push_back(o);
		else if (auto sf =
		             std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj))
			for (const auto& so : *sf) pending_.push_back(so);
		else if (std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(obj))
			continue;  // odometry actions are not used by bims
		else  // (the guard refuses such objects before MRPT reads them)
			throw RawlogError(
			    path_ + ": entry " + std::to_string(entry_) + " is a " +
			    obj->GetRuntimeClass()->className +
			    ", not an observation, sensory frame or action collection");
	}
	auto o = pending_.front();
	pending_.pop_front();
	++nObs_;
	return o;
}

RawlogWriter::RawlogWriter(const std::string& path, int gzLevel) : path_(path)
{
	if (gzLevel < 0 || gzLevel > 9)
		throw RawlogError(path + ": gzip level must be in 0..9");
	try
	{
		if (gzLevel == 0)
			plain_ = std::make_unique<AppendFile>(path);
		else
			gz_ = std::make_unique<GzipMemberWriter>(path, gzLevel,
			                                         kCompressionThreads);
	}
	catch (const std::exception& e)
	{
		throw RawlogError(std::string(e.what()) + " (rawlog file)");
	}
	arch_ = std::make_unique<VectorArchive>(buf_);
	open_ = true;
}

RawlogWriter::~RawlogWriter()
{
	try
	{
		close();
	}
	catch (...)
	{
	}
}

void RawlogWriter::write(const mrpt::obs::CObservation& obs)
{
	if (!open_) throw RawlogError(path_ + ": write after close");
	buf_.clear();
	try
	{
		*arch_ << obs;
	}
	catch (const std::exception& e)
	{
		throw RawlogError(path_ + ": write failed: " + e.what());
	}
	try
	{
		if (plain_)
			plain_->append(buf_.data(), buf_.size());
		else
			gz_->append(buf_.data(), buf_.size());
	}
	catch (const std::exception& e)
	{
		throw RawlogError(e.what());
	}
	++n_;
}

void RawlogWriter::flush()
{
	// a plain rawlog reaches the OS object by object (AppendFile); a gzip
	// one ends its member and waits for it to be in the file
	if (!gz_) return;
	try
	{
		gz_->flush();
	}
	catch (const std::exception& e)
	{
		throw RawlogError(e.what());
	}
}

void RawlogWriter::close()
{
	if (!open_) return;
	open_ = false;
	arch_.reset();
	auto plain = std::move(plain_);
	auto gz = std::move(gz_);
	try
	{
		if (plain) plain->close();
		if (gz) gz->close();
	}
	catch (const std::exception& e)
	{
		throw RawlogError(e.what());
	}
}

}  // namespace bims
