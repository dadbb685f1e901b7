// Fuzz target: the .ini syntax check and the strict reading of a whole
// experiment file (every section, key and range).
#include <bims/common/config.h>
#include <bims/pipeline/config.h>

#include <exception>

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	const std::string path = bims::fuzz::writeFile("in.ini", data, size);
	try
	{
		bims::checkIniFile(path);
		bims::pipeline::ExperimentConfig cfg;
		cfg.loadFromFile(path);
	}
	catch (const std::exception&)
	{
		// a clear error is the expected answer to a bad file
	}
	return 0;
}
