// A depth (or range) image as the sensor gives it: 16-bit readings in sensor
// units (0 = no reading), the one raw form every stage reads depth from
// (MRPT's CObservation3DRangeScan::rangeImage, a TUM/Bonn PNG, a phone's
// LiDAR, a NumPy array). A view: it does not own the readings.
#pragma once

#include <mrpt/core/Clock.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace mrpt::obs
{
class CObservation3DRangeScan;
}

namespace bims
{
struct DepthImage
{
	const uint16_t* data = nullptr;  ///< row-major readings
	int width = 0, height = 0;
	size_t stride = 0;  ///< readings from one row to the next
	float units = 0;    ///< metres per unit (MRPT's rangeUnits)
	/** Optical-axis depth (MRPT's range_is_depth); false: Euclidean range
	 * from the optical centre. */
	bool isDepth = true;
	mrpt::Clock::time_point timestamp{};  ///< INVALID_TIMESTAMP if unknown
	std::string label;                    ///< the sensor, for messages

	bool empty() const { return !data || width <= 0 || height <= 0; }
	const uint16_t* row(int v) const { return data + size_t(v) * stride; }
};

/** The range image of \a scan (empty without one) with its units, kind,
 * stamp and label: a view valid while the scan lives, unchanged. The scan
 * must be loaded (external storage). */
DepthImage depthImageOf(const mrpt::obs::CObservation3DRangeScan& scan);

}  // namespace bims
