// Fuzz target: a ROS 2 MCAP file as bims-import-bag reads it (bims/bag/
// bag_import.h): bims's own MCAP reader (libs/bag/src/mcap_file.cpp: the
// records, schemas, channels, chunks, zstd and lz4 decompression, CRCs, the
// summary, a file cut short), the CDR messages (cdr.cpp), then the import
// proper into a plain rawlog; and the topics as --topics lists them (the
// summary's counts). The file is mapped: the input is written to this
// process's scratch folder (TMPDIR; /dev/shm is a good one).
#include "fuzz_bag_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	bims::fuzz::importBagInput("input.mcap", data, size, true);
	return 0;
}
