// Fuzz target: a ROS 1 bag as bims-import-bag reads it (bims/bag/
// bag_import.h): bims's reading of its records (bag_file.h: connections,
// chunks, LZ4 and BZ2 decompression, a bag cut short), then the import
// proper: the layout found from its topics, the stamps, CameraInfo, the IMU
// streams, the images raw and compressed (the guarded decoding), into a
// plain rawlog. The bag is mapped from a file: the input is written to this
// process's scratch folder (TMPDIR; /dev/shm is a good one).
#include "fuzz_bag_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	bims::fuzz::importBagInput("input.bag", data, size, false);
	return 0;
}
