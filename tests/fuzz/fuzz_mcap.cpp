// Fuzz target: a ROS 2 MCAP file as bims-import-bag reads it (bims/bag/
// bag_import.h): bims's own MCAP reader (libs/bag/src/mcap_file.cpp: the
// records, schemas, channels, chunks, zstd and lz4 decompression, CRCs, the
// summary, a file cut short), the CDR messages (cdr.cpp), then the import
// proper into a plain rawlog; and the topics as --topics lists them (the
// summary's counts). The file is mapped: the input is written to this
// process's scratch folder (TMPDIR; /dev/shm is a good one).
#include <bims/bag/bag_import.h>

#include <exception>
#include <filesystem>
#include <string>

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	const std::string bag = bims::fuzz::writeFile("input.mcap", data, size);
	const std::string out = bims::fuzz::scratchDir() + "/out.rawlog";
	try
	{
		(void)bims::bag::bagTopics({bag});
	}
	catch (const std::exception&)
	{
	}
	try
	{
		bims::bag::BagImportOptions o;
		o.gzLevel = 0;
		(void)bims::bag::importBag({bag}, out, bims::bag::BagImportParams{}, o);
	}
	catch (const std::exception&)
	{
		// a clear error is the expected answer to a bad file
	}
	std::error_code ec;
	std::filesystem::remove(out, ec);
	std::filesystem::remove(out + ".partial", ec);
	return 0;
}
