// Fuzz target: the rawlog reader (every program reads rawlogs through it,
// with the scan-size guard before MRPT allocates) and the checks a frame
// passes before use (rgbdFrameFrom, the IMU sample conversion).
#include <bims/ego/attitude_filter.h>
#include <bims/ego/rgbd_input.h>
#include <bims/io/rawlog.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <exception>
#include <string>

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	using namespace mrpt::obs;
	const std::string path = bims::fuzz::writeFile("in.rawlog", data, size);
	try
	{
		bims::RawlogReader reader(path);
		for (int k = 0; k < 256; k++)
		{
			const CObservation::Ptr o = reader.next();
			if (!o) break;
			if (const auto s =
			        std::dynamic_pointer_cast<CObservation3DRangeScan>(o))
			{
				bims::ego::RgbdFrame f;
				(void)bims::ego::rgbdFrameFrom(
				    *s, bims::sensors::CameraParams{}, f);
			}
			else if (const auto imu =
			             std::dynamic_pointer_cast<CObservationIMU>(o))
				(void)bims::sensors::imuSampleFrom(*imu);
		}
	}
	catch (const std::exception&)
	{
		// a clear error is the expected answer to a bad file
	}
	return 0;
}
