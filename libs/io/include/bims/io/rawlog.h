// Streaming rawlog input/output with errors that name the file and the entry.
//
// Reads both MRPT rawlog formats (observations-only and actions/sensory-frames;
// observations inside a sensory frame are returned one by one). A truncated or
// corrupt file raises RawlogError instead of ending silently.
#pragma once

#include <bims/io/output_paths.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CObservation.h>
#include <mrpt/serialization/CArchive.h>

#include <deque>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace bims
{
class GzipMemberWriter;

/** Error reading or writing a rawlog; the message names the file. */
class RawlogError : public std::runtime_error
{
 public:
	using std::runtime_error::runtime_error;
};

/** The external-images folder MRPT would use for a rawlog
 * ("<path without extension>_Images"), computed correctly (MRPT 2.5.8's
 * CRawlog::detectImagesDirectory() drops a '/'). */
std::string rawlogImagesDirectory(const std::string& rawlogPath);

/** The bytes of data a rawlog file holds, for showing how far a reading
 * has come: its size; for a gzip file, the size of the data inside
 * (gzipDataBytes: exact for RawlogWriter's files, an estimate for other
 * writers' past 4 GiB or of several members). 0 when the file cannot be
 * read. */
uint64_t rawlogDataBytes(const std::string& path);

/** Throws RawlogError naming \a path unless it is a readable regular file:
 * missing, a folder (with the importer to use when it is a TUM RGB-D folder
 * or a Stray Scanner capture), empty (0 bytes: no rawlog, not even a gzip
 * header), or unreadable. Programs check every input
 * rawlog with it before they write anything. */
void checkRawlogPath(const std::string& path);

class RawlogReader
{
 public:
	/** Opens the file (plain or gzip); throws RawlogError if it cannot. Sets
	 * CImage's external images base path to rawlogImagesDirectory(path) when
	 * that folder exists. */
	explicit RawlogReader(const std::string& path);

	/** Next observation, or nullptr at the clean end of the file. Throws
	 * RawlogError naming the file and the entry on truncation or corruption. */
	[[nodiscard]] mrpt::obs::CObservation::Ptr next();

	/** Bytes of data read so far (decompressed), of rawlogDataBytes(). */
	uint64_t bytesRead() const;
	/** Index of the last serialized object read (0-based), -1 before any. */
	long entryIndex() const { return entry_; }
	/** Number of observations returned so far. */
	size_t observationsRead() const { return nObs_; }
	const std::string& path() const { return path_; }

 private:
	std::string path_;
	mrpt::io::CFileGZInputStream in_;
	std::unique_ptr<mrpt::serialization::CArchive> arch_;
	std::deque<mrpt::obs::CObservation::Ptr> pending_;
	long entry_ = -1;
	size_t nObs_ = 0;
	bool atEnd_ = false;
};

/** The 3D scans (CObservation3DRangeScan) of \a rawlogs read one after the
 * other, with sensor label \a label (any when empty), counted up to \a
 * atMost (reading stops there). Throws RawlogError as RawlogReader does. */
size_t count3DScans(const std::vector<std::string>& rawlogs,
                    const std::string& label, size_t atMost);

class RawlogWriter
{
 public:
	/** Creates (truncates) \a path (a symbolic link there is replaced, its
	 * target untouched). gzLevel 1..9 writes a gzip-compressed rawlog, 0 a
	 * plain one (for live grabbing). Throws RawlogError if the file cannot
	 * be created.
	 *
	 * A gzip rawlog is written as independent gzip members of ~2 MB of
	 * whole observations (GzipMemberWriter: compressed on worker threads,
	 * written in order; every gzip reader reads them as one stream). The
	 * members end where the writes and flushes say, never by timing: the
	 * same observations give the same file byte for byte. */
	explicit RawlogWriter(const std::string& path, int gzLevel = 1);
	~RawlogWriter();
	RawlogWriter(const RawlogWriter&) = delete;
	RawlogWriter& operator=(const RawlogWriter&) = delete;

	/** Appends one observation (observations-only rawlog format). A plain
	 * rawlog gets it at once or not at all (bims::AppendFile: a failed write
	 * leaves the file at its last whole observation and throws naming it); a
	 * gzip rawlog gets it in its current member, and a member that cannot be
	 * written leaves the file at its last whole member and throws naming it
	 * at this call or the next (write, flush or close). */
	void write(const mrpt::obs::CObservation& obs);
	/** Everything written so far reaches the OS: a killed program leaves
	 * the file readable up to here. Nothing to do for a plain rawlog (each
	 * object reaches the OS when written); a gzip rawlog ends its current
	 * member and waits until it is in the file (a whole gzip file: ~40 bytes
	 * more per call, and the next member starts without the dictionary of
	 * the data before). Throws RawlogError naming the file if the write
	 * fails. */
	void flush();
	/** Closes the file; throws RawlogError naming it if the last bytes
	 * could not be written (plain and gzip rawlogs). */
	void close();
	size_t written() const { return n_; }
	const std::string& path() const { return path_; }

 private:
	std::string path_;
	/** Workers compressing a gzip rawlog's members (the caller serializes
	 * beside them). */
	static constexpr int kCompressionThreads = 2;
	std::unique_ptr<AppendFile> plain_;     ///< a plain rawlog
	std::unique_ptr<GzipMemberWriter> gz_;  ///< a gzip rawlog
	std::vector<uint8_t> buf_;              ///< the object being written
	std::unique_ptr<mrpt::serialization::CArchive> arch_;
	bool open_ = false;
	size_t n_ = 0;
};

}  // namespace bims
