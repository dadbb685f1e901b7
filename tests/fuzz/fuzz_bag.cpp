// Fuzz target: a ROS 1 bag as bims-import-bag reads it (bims/bag/
// bag_import.h): bims's reading of its records (bag_file.h: connections,
// chunks, LZ4 and BZ2 decompression, a bag cut short), then the import
// proper: the layout found from its topics, the stamps, CameraInfo, the IMU
// streams, the images raw and compressed (the guarded decoding), into a
// plain rawlog. The bag is mapped from a file: the input is written to this
// process's scratch folder (TMPDIR; /dev/shm is a good one).
#include <bims/bag/bag_import.h>

#include <exception>
#include <filesystem>
#include <string>

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	const std::string bag = bims::fuzz::writeFile("input.bag", data, size);
	const std::string out = bims::fuzz::scratchDir() + "/out.rawlog";
	try
	{
		bims::bag::BagImportOptions o;
		o.gzLevel = 0;
		(void)bims::bag::importBag({bag}, out, bims::bag::BagImportParams{}, o);
	}
	catch (const std::exception&)
	{
		// a clear error is the expected answer to a bad bag
	}
	std::error_code ec;
	std::filesystem::remove(out, ec);
	std::filesystem::remove(out + ".partial", ec);
	return 0;
}
