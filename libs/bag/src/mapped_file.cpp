#include "mapped_file.h"

#include <bims/common/input_file.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace bims::bag
{
MappedFile mapFile(const std::string& path)
{
	using std::runtime_error;
	MappedFile f;
	// a regular file only (a FIFO would block the open): what it is named
	if (const std::string why = inputFileProblem(path); !why.empty())
		throw runtime_error(why);
	const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
	if (fd < 0)
		throw runtime_error(std::string("cannot be opened: ") +
		                    std::strerror(errno));
	struct stat st = {};
	if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
	{
		::close(fd);
		throw runtime_error("not a regular file");
	}
	f.size = static_cast<uint64_t>(st.st_size);
	if (f.size == 0)
	{
		::close(fd);
		return f;
	}
	void* p = ::mmap(nullptr, f.size, PROT_READ, MAP_PRIVATE, fd, 0);
	const int err = errno;
	::close(fd);
	if (p == MAP_FAILED)
		throw runtime_error(std::string("cannot be mapped: ") +
		                    std::strerror(err));
	::madvise(p, f.size, MADV_SEQUENTIAL);
	const uint64_t n = f.size;
	f.owner = std::shared_ptr<const void>(
	    p, [n](const void* q) { ::munmap(const_cast<void*>(q), n); });
	f.bytes = static_cast<const uint8_t*>(p);
	return f;
}

}  // namespace bims::bag
