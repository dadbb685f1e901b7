// A gzip file written as independent members (RFC 1952, 2.2: a gzip file is
// a series of members), each compressed whole with libdeflate on a worker
// thread, written in order. zlib's gzread (MRPT's CFileGZInputStream, so
// bims::RawlogReader), Python's gzip module and zcat read the members as one
// stream.
//
// Each member's header carries an extra field (FEXTRA, subfield 'B' 'm')
// with the member's compressed size and its data's size (64 bits each):
// gzipDataBytes() walks the members by it, where the trailer of the last
// member alone gives only that member's size.
#pragma once

#include <bims/io/output_paths.h>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace bims
{
/** Bytes of data a member holds before it is handed to a worker (it ends
 * at the first append() that reaches it, or at flush()). */
inline constexpr size_t kGzipMemberBytes = size_t(2) << 20;

class GzipMemberWriter
{
 public:
	/** Creates (truncates) \a path (a symbolic link there is replaced, its
	 * target untouched) and starts \a threads workers (at least 1)
	 * compressing at \a level (1..9, as gzip's). Throws std::runtime_error
	 * naming the file if it cannot be created. */
	GzipMemberWriter(std::string path, int level, int threads = 2,
	                 size_t memberBytes = kGzipMemberBytes);
	/** Closes (errors dropped: call close() to see them). */
	~GzipMemberWriter();
	GzipMemberWriter(const GzipMemberWriter&) = delete;
	GzipMemberWriter& operator=(const GzipMemberWriter&) = delete;

	/** Appends \a n bytes to the current member; once it holds memberBytes
	 * it goes to the workers (waiting while a few members are in flight).
	 * The members' boundaries depend on the appends and flushes only, so the
	 * file is the same byte for byte for the same calls. Throws
	 * std::runtime_error naming the file if a member could not be written
	 * (the file ends at its last whole member: AppendFile). */
	void append(const void* data, size_t n);
	/** Ends the current member and waits until every member is in the file
	 * (reached the OS): a killed program leaves a whole gzip file up to
	 * here. Throws as append() does. */
	void flush();
	/** Writes the rest and closes the file (a file of no data gets one empty
	 * member: a valid gzip file). Throws naming the file if that fails or a
	 * member failed before. */
	void close();
	const std::string& path() const { return file_.path(); }

 private:
	struct Job
	{
		uint64_t seq = 0;
		std::vector<uint8_t> data;
	};
	void submit();
	void work();
	void throwIfFailed();

	AppendFile file_;
	const int level_;
	const size_t memberBytes_;
	const size_t maxInFlight_;
	std::vector<uint8_t> current_;  ///< the member being filled
	std::mutex m_;
	std::condition_variable cv_;
	std::deque<Job> jobs_;    ///< members waiting for a worker
	uint64_t submitted_ = 0;  ///< members handed to the workers
	uint64_t written_ = 0;    ///< members in the file (or dropped on error)
	std::string error_;       ///< the first failure
	bool stop_ = false, closed_ = false;
	std::vector<std::thread> workers_;  // last: started once the rest is built
};

/** One gzip member of \a n bytes of \a data at \a level (1..9) as
 * GzipMemberWriter writes it (header with the sizes' extra field, raw
 * DEFLATE, CRC-32 and size trailer). */
std::vector<uint8_t> gzipMember(const void* data, size_t n, int level);

/** The bytes of data the gzip file \a path holds: the sum of its members'
 * data sizes when every member carries GzipMemberWriter's extra field;
 * otherwise its last member's trailer (modulo 4 GiB: taken as the smallest
 * such size not below the compressed size, an estimate for files of other
 * writers with several members or past 4 GiB). A whole file that is not
 * gzip: its size. 0 when it cannot be read. */
uint64_t gzipDataBytes(const std::string& path);

}  // namespace bims
