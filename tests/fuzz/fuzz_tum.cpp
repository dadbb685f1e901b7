// Fuzz target: the TUM / Bonn folder index (rgb.txt, depth.txt,
// groundtruth.txt, accelerometer.txt: the input's parts, separated by lines
// "--"; an empty part is a missing file) and the TUM trajectory reader.
#include <bims/eval/tum_import.h>
#include <bims/io/trajectory.h>

#include <cstdio>
#include <exception>
#include <filesystem>

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	namespace fs = std::filesystem;
	const char* names[] = {"rgb.txt", "depth.txt", "groundtruth.txt",
	                       "accelerometer.txt"};
	const auto parts = bims::fuzz::splitParts(data, size, 4);
	const std::string dir = bims::fuzz::scratchDir() + "/tum";
	fs::create_directories(dir);
	for (size_t i = 0; i < 4; i++)
	{
		const std::string p = "tum/" + std::string(names[i]);
		if (parts[i].empty())
			std::remove((bims::fuzz::scratchDir() + "/" + p).c_str());
		else
			bims::fuzz::writeFile(
			    p, reinterpret_cast<const uint8_t*>(parts[i].data()),
			    parts[i].size());
	}
	try
	{
		(void)bims::eval::readTumFolder(dir, bims::eval::ImportParams{});
	}
	catch (const std::exception&)
	{
	}
	try
	{
		if (!parts[2].empty())
			(void)bims::loadTumTrajectory(dir + "/groundtruth.txt");
	}
	catch (const std::exception&)
	{
	}
	return 0;
}
