#include <bims/common/input_file.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace bims
{
namespace
{
const char* const kOnlyRegular =
    "bims reads only regular files: a pipe or a device could block or never "
    "end";

/** What a file of mode \a m is, when it is not a regular file; "" when it
 * is one. */
std::string typeProblem(mode_t m)
{
	if (S_ISREG(m)) return "";
	if (S_ISDIR(m)) return "a folder, not a file";
	const char* kind = S_ISFIFO(m)   ? "a FIFO (named pipe)"
	                   : S_ISCHR(m)  ? "a character device"
	                   : S_ISBLK(m)  ? "a block device"
	                   : S_ISSOCK(m) ? "a socket"
	                                 : "not a regular file";
	return std::string(kind) + ", not a regular file (" + kOnlyRegular + ")";
}

/** Why stat(2) of \a path failed with \a err. */
std::string statProblem(const std::string& path, int err)
{
	if (err == ELOOP)
		return "a symbolic link loop (too many levels of symbolic links)";
	if (err == ENOENT)
	{
		struct stat l;
		if (::lstat(path.c_str(), &l) == 0 && S_ISLNK(l.st_mode))
		{
			std::vector<char> to(4096);
			const ssize_t n = ::readlink(path.c_str(), to.data(), to.size());
			return "a symbolic link to nothing (" +
			       (n > 0 ? std::string(to.data(), static_cast<size_t>(n))
			              : std::string("?")) +
			       ")";
		}
		return "no such file";
	}
	if (err == ENOTDIR) return "a part of the path is not a folder";
	return std::strerror(err);
}

std::runtime_error cannotRead(const std::string& path, const std::string& what,
                              const std::string& why)
{
	return std::runtime_error(path + ": cannot read " + what + ": " + why);
}
}  // namespace

std::string inputFileProblem(const std::string& path)
{
	if (path.empty()) return "no file named (an empty path)";
	struct stat st;
	if (::stat(path.c_str(), &st) != 0) return statProblem(path, errno);
	return typeProblem(st.st_mode);
}

void checkInputFile(const std::string& path, const std::string& what)
{
	const std::string why = inputFileProblem(path);
	if (!why.empty()) throw cannotRead(path, what, why);
}

InputFile::InputFile(std::string path, std::string what)
    : path_(std::move(path)), what_(std::move(what))
{
	checkInputFile(path_, what_);
	// O_NONBLOCK: a FIFO put there since the check is opened at once (and
	// refused below) instead of waiting for a writer
	fd_ = ::open(path_.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
	if (fd_ < 0) throw cannotRead(path_, what_, statProblem(path_, errno));
	struct stat st;
	std::string why;
	if (::fstat(fd_, &st) != 0)
		why = std::strerror(errno);
	else
		why = typeProblem(st.st_mode);
	if (!why.empty())
	{
		::close(fd_);
		fd_ = -1;
		throw cannotRead(path_, what_, why);
	}
	size_ = static_cast<uint64_t>(st.st_size);
	// a regular file: reads block as usual
	const int flags = ::fcntl(fd_, F_GETFL);
	if (flags >= 0) ::fcntl(fd_, F_SETFL, flags & ~O_NONBLOCK);
}

InputFile::~InputFile()
{
	if (fd_ >= 0) ::close(fd_);
}

size_t InputFile::read(void* p, size_t n)
{
	for (;;)
	{
		const ssize_t k = ::read(fd_, p, n);
		if (k >= 0) return static_cast<size_t>(k);
		if (errno == EINTR) continue;
		throw cannotRead(path_, what_, std::strerror(errno));
	}
}

LineReader::LineReader(std::string path, std::string what, size_t maxLine)
    : file_(std::move(path), std::move(what)), maxLine_(maxLine)
{
}

bool LineReader::fill()
{
	if (eof_) return false;
	if (pos_ > 0)
	{
		buf_.erase(0, pos_);
		pos_ = 0;
	}
	const size_t old = buf_.size();
	constexpr size_t kChunk = 64 * 1024;
	buf_.resize(old + kChunk);
	const size_t n = file_.read(&buf_[old], kChunk);
	buf_.resize(old + n);
	if (n == 0) eof_ = true;
	if (!started_ && (buf_.size() >= 3 || eof_))
	{
		started_ = true;
		if (buf_.compare(0, 3, "\xEF\xBB\xBF") == 0)
		{
			bom_ = true;
			pos_ = 3;
		}
	}
	return n > 0;
}

bool LineReader::next(std::string& line)
{
	size_t scanned = 0;  // bytes from pos_ known to hold no line end
	for (;;)
	{
		if (!started_)
		{
			fill();
			continue;
		}
		size_t i = pos_ + scanned;
		while (i < buf_.size() && buf_[i] != '\n' && buf_[i] != '\r') i++;
		if (i - pos_ > maxLine_)
			throw std::runtime_error(
			    file_.path() + ":" + std::to_string(line_ + 1) +
			    ": a line longer than " + std::to_string(maxLine_) +
			    " bytes: not a " + file_.what() +
			    " (binary bytes, or another file in its place?)");
		if (i < buf_.size())
		{
			// "\r\n" is one line end: the byte after a '\r' is needed
			if (buf_[i] == '\r' && i + 1 == buf_.size() && !eof_)
			{
				scanned = i - pos_;
				fill();
				continue;
			}
			line.assign(buf_, pos_, i - pos_);
			size_t end = i + 1;
			if (buf_[i] == '\r' && end < buf_.size() && buf_[end] == '\n')
				end++;
			pos_ = end;
			line_++;
			return true;
		}
		scanned = i - pos_;
		if (eof_)
		{
			if (pos_ == buf_.size()) return false;
			line.assign(buf_, pos_, std::string::npos);
			pos_ = buf_.size();
			line_++;
			return true;
		}
		fill();
	}
}

}  // namespace bims
