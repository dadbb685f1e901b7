// Fuzz target: one ROS 2 message as CDR, read by bims's decoder
// (libs/bag/src/cdr.cpp) as the type the first byte chooses: Image,
// CompressedImage, CameraInfo, Imu, MagneticField, or a header's stamp
// alone. Every length is to be checked against the bytes before use: a
// read beyond them, an allocation from a declared length or undefined
// behaviour is a finding.
#include <cstddef>
#include <cstdint>
#include <exception>

#include <bims/bag/cdr.h>
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	if (size == 0) return 0;
	namespace cdr = bims::bag::cdr;
	const uint8_t* p = data + 1;
	const size_t n = size - 1;
	try
	{
		switch (data[0] % 6)
		{
			case 0:
			{
				const auto v = cdr::image(p, n);
				// the pixels are where the message is: touch the last
				if (v.size > 0)
					(void)*(volatile const uint8_t*)(v.data + v.size - 1);
				break;
			}
			case 1:
			{
				const auto v = cdr::compressedImage(p, n);
				if (v.size > 0)
					(void)*(volatile const uint8_t*)(v.data + v.size - 1);
				break;
			}
			case 2:
				(void)cdr::cameraInfo(p, n);
				break;
			case 3:
				(void)cdr::imu(p, n);
				break;
			case 4:
				(void)cdr::magneticField(p, n);
				break;
			default:
				(void)cdr::headerStamp(p, n);
				break;
		}
	}
	catch (const std::exception&)
	{
		// a clear error is the expected answer to a bad message
	}
	return 0;
}
