#include <bims/common/app.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <cstdio>
#include <filesystem>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <stdexcept>

namespace bims
{
void keepFreedMemoryForReuse()
{
#if defined(__GLIBC__)
	// Blocks up to 32 MB (glibc's largest threshold) from the heap instead
	// of a mapping of their own, and the heap's free top kept up to 1 GB:
	// with the defaults, buffers of a few MB freed on one thread and
	// allocated again on another went back to the system and came back as
	// zeroed pages (two thirds of the page faults of a bims-run).
	mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
	mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);
#endif
}

int runApp(const std::string& program, const std::function<int()>& body)
{
	try
	{
		return body();
	}
	catch (const ExitRequest& e)
	{
		return e.code;
	}
	catch (const TCLAP::ArgException& e)
	{
		std::fprintf(stderr, "%s: usage error: %s (%s)\n", program.c_str(),
		             e.error().c_str(), e.argId().c_str());
		return 2;
	}
	catch (const UsageError& e)
	{
		std::fprintf(stderr, "%s: usage error: %s\n", program.c_str(),
		             e.what());
		return 2;
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "%s: error: %s\n", program.c_str(), e.what());
		return 1;
	}
}

void makeDirs(const std::string& path)
{
	std::error_code ec;
	std::filesystem::create_directories(path, ec);
	if (ec)
		throw std::runtime_error(path +
		                         ": cannot create directory: " + ec.message());
}

}  // namespace bims
