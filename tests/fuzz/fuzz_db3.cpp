// Fuzz target: a ROS 2 sqlite3 bag (.db3) as bims-import-bag reads it
// (libs/bag/src/db3_file.cpp over Debian's libsqlite3, read-only: its
// tables, topics, messages), the CDR messages, then the import proper into
// a plain rawlog, and the topics as --topics lists them. The input is
// written to this process's scratch folder.
#include <bims/bag/bag_import.h>

#include <exception>
#include <filesystem>
#include <string>

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	const std::string bag = bims::fuzz::writeFile("input.db3", data, size);
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
