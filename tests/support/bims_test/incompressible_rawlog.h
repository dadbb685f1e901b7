// A gzip rawlog that does not compress, written on a full disk: for the
// writer's error paths (bims/io/rawlog.h).
#pragma once

#include <bims/io/rawlog.h>
#include <bims_test/file_size_limit.h>
#include <mrpt/obs/CObservationIMU.h>

#include <cstdint>
#include <string>

namespace bims::test
{
/** Writes \a n IMU observations stamped 10, 11, ... s, each with a label of
 * \a bytes pseudo-random bytes (they do not compress), into the gzip
 * rawlog \a path (level \a gzLevel), in a child whose files may not grow
 * beyond \a limit bytes (exitOfChildWithFileSizeLimit). Returns 0 when all
 * was written, 3 when a RawlogError starting with \a errorStart names "File
 * too large", 4 for another RawlogError, -1 when the child did not exit. */
inline int writeIncompressibleOnAFullDisk(const std::string& path, int gzLevel,
                                          rlim_t limit, int n, int bytes,
                                          const std::string& errorStart)
{
	return exitOfChildWithFileSizeLimit(
	    limit,
	    [&]
	    {
		    try
		    {
			    RawlogWriter w(path, gzLevel);
			    uint32_t x = 12345;
			    for (int i = 0; i < n; i++)
			    {
				    mrpt::obs::CObservationIMU imu;
				    imu.timestamp = mrpt::Clock::fromDouble(10.0 + i);
				    for (int k = 0; k < bytes; k++)
				    {
					    x = x * 1664525u + 1013904223u;
					    imu.sensorLabel += static_cast<char>(x >> 24);
				    }
				    w.write(imu);
			    }
			    w.close();
			    return 0;
		    }
		    catch (const RawlogError& e)
		    {
			    const std::string m = e.what();
			    return m.rfind(errorStart, 0) == 0 &&
			                   m.find("File too large") != std::string::npos
			               ? 3
			               : 4;
		    }
	    });
}
}  // namespace bims::test
