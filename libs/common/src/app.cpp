#include <bims/common/app.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace bims
{
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
