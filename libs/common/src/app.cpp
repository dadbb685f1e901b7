#include <bims/common/app.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <sstream>
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

namespace
{
std::atomic<bool> gStop{false};
std::atomic<int> gStopSignal{0};

extern "C" void onStopSignal(int sig)
{
	gStopSignal = sig;
	gStop = true;
	// a second signal kills at once (default action)
	std::signal(SIGINT, SIG_DFL);
	std::signal(SIGTERM, SIG_DFL);
}
}  // namespace

const std::atomic<bool>& installStopSignals()
{
	std::signal(SIGINT, onStopSignal);
	std::signal(SIGTERM, onStopSignal);
	return gStop;
}

int stopSignal()
{
	return gStopSignal;
}

void makeDirs(const std::string& path)
{
	std::error_code ec;
	std::filesystem::create_directories(path, ec);
	if (ec)
		throw std::runtime_error(path +
		                         ": cannot create directory: " + ec.message());
}

std::set<size_t> parseIndexList(const std::string& text,
                                const std::string& flag)
{
	std::set<size_t> out;
	std::stringstream ss(text);
	std::string tok;
	while (std::getline(ss, tok, ','))
	{
		size_t used = 0;
		unsigned long v = 0;
		try
		{
			v = std::stoul(tok, &used);
		}
		catch (const std::exception&)
		{
			used = 0;
		}
		if (used == 0 || used != tok.size() || tok[0] == '-')
			throw UsageError(flag + ": bad index '" + tok + "'");
		out.insert(static_cast<size_t>(v));
	}
	return out;
}

}  // namespace bims
