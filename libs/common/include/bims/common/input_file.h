// The one rule for the files bims reads as input (CSVs, images, videos,
// lists): only a regular file is read. A FIFO would block the program
// forever (its open waits for a writer), a device like /dev/zero never
// ends; both are refused with an error naming the file and what it is,
// before anything is read. A path that does not resolve is named with the
// real reason (no such file, a symbolic link loop, a link to nothing,
// permission). Text files are read line by line with a bound on a line's
// length (LineReader): a file of one endless line is an error naming it,
// not gigabytes of memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace bims
{
/** Why \a path cannot be read as an input file; "" when it is a regular
 * file (symbolic links followed). E.g. "a FIFO (named pipe), not a regular
 * file", "a folder, not a file", "no such file", "a symbolic link loop (too
 * many levels of symbolic links)", "a symbolic link to nothing (TARGET)". */
std::string inputFileProblem(const std::string& path);

/** Throws std::runtime_error "PATH: cannot read WHAT: WHY" (inputFileProblem)
 * unless \a path is a regular file. \a what: e.g. "depth image", "video". */
void checkInputFile(const std::string& path, const std::string& what);

/** An input file opened for reading: checked as checkInputFile() before it
 * is opened, and again on the open descriptor (opened without blocking, so
 * a FIFO put in its place meanwhile is refused, never waited on). */
class InputFile
{
 public:
	InputFile(std::string path, std::string what);
	~InputFile();
	InputFile(const InputFile&) = delete;
	InputFile& operator=(const InputFile&) = delete;

	/** The file's size when opened [bytes]. */
	uint64_t size() const { return size_; }
	/** Reads up to \a n bytes; 0 at the end. Throws naming the file. */
	size_t read(void* p, size_t n);
	const std::string& path() const { return path_; }
	const std::string& what() const { return what_; }

 private:
	std::string path_, what_;
	int fd_ = -1;
	uint64_t size_ = 0;
};

/** The longest line LineReader takes by default [bytes]: far above any row
 * of the text files bims reads. */
constexpr size_t kMaxLineBytes = 64 * 1024;

/** A text input file read line by line, one line in memory at a time. Lines
 * end with "\n", "\r\n" or a lone "\r" (old Mac files), the last one
 * possibly with none; a UTF-8 byte-order mark at the start is skipped (a
 * spreadsheet's export). A line longer than \a maxLine is an error
 * "PATH:LINE: a line longer than N bytes ...". */
class LineReader
{
 public:
	LineReader(std::string path, std::string what,
	           size_t maxLine = kMaxLineBytes);

	/** The next line, without its end; false at the end of the file. */
	bool next(std::string& line);
	/** The 1-based number of the line next() returned last. */
	size_t lineNumber() const { return line_; }
	/** Whether the file started with a UTF-8 byte-order mark (skipped). */
	bool hadByteOrderMark() const { return bom_; }
	const std::string& path() const { return file_.path(); }

 private:
	bool fill();

	InputFile file_;
	size_t maxLine_;
	std::string buf_;
	size_t pos_ = 0;
	bool eof_ = false, started_ = false, bom_ = false;
	size_t line_ = 0;
};

}  // namespace bims
