// Fuzz target: a ROS 2 sqlite3 bag (.db3) as bims-import-bag reads it
// (libs/bag/src/db3_file.cpp over Debian's libsqlite3, read-only: its
// tables, topics, messages), the CDR messages, then the import proper into
// a plain rawlog, and the topics as --topics lists them. The input is
// written to this process's scratch folder.
#include "fuzz_bag_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	bims::fuzz::importBagInput("input.db3", data, size, true);
	return 0;
}
