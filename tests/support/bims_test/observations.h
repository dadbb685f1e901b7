// The 3D scans and IMU observations of a rawlog, in order, for tests that
// compare what an importer wrote with the bundled sample.
#pragma once

#include <bims/io/rawlog.h>
#include <bims_test/sample.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <string>
#include <vector>

namespace bims::test
{
struct Observations
{
	std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> frames;
	std::vector<mrpt::obs::CObservationIMU::Ptr> imu;
};

/** The scans and IMU observations of \a path; with \a maxFrames > 0 up to
 * that many scans (each loaded: external images read in). */
inline Observations readObservations(const std::string& path,
                                     size_t maxFrames = 0)
{
	Observations r;
	RawlogReader in(path);
	while (auto o = in.next())
	{
		if (auto f =
		        std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
		            o))
		{
			if (maxFrames > 0) f->load();
			r.frames.push_back(f);
			if (r.frames.size() == maxFrames) break;
		}
		else if (auto m =
		             std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o))
			r.imu.push_back(m);
	}
	return r;
}

/** The first 24 frames of the bundled sample and the IMU samples up to
 * them (read once). */
inline const Observations& sampleObservations()
{
	static const Observations s = readObservations(kSample, 24);
	return s;
}
}  // namespace bims::test
