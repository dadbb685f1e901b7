// Fuzz target: an image file as every importer and bims-eval read it
// (bims/io/image_file.h): the header check (PNG, JPEG, TIFF, BMP; the
// declared size against the limits before anything is decoded), then the
// decoding, as stored (depth, labels) and as colour.
#include <bims/io/image_file.h>

#include <exception>
#include <opencv2/imgcodecs.hpp>

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	(void)bims::imageHeader(data, size);
	const std::string path = bims::fuzz::writeFile("image", data, size);
	for (const int flags : {cv::IMREAD_UNCHANGED, cv::IMREAD_COLOR})
	{
		try
		{
			(void)bims::readImageFile(path, flags, "fuzzed image");
		}
		catch (const std::exception&)
		{
		}
	}
	return 0;
}
