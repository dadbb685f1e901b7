// A small RGB-D source over OpenNI2 (not MRPT's COpenNI2Sensor, which aborts
// without a device and refuses file and Dummy devices: MRPT_NOTES.md §6).
// Opens a real sensor (Kinect / Xtion), OpenNI2's Dummy device (URI "Dummy")
// or an .oni recording (a file path) and turns each depth frame and the
// newest colour frame into a CObservation3DRangeScan on the host clock.
#pragma once

#include <bims/grab/host_clock.h>

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <memory>
#include <string>

namespace bims::grab
{
/** One [SECTION] with driver=OpenNI2 of the grab .ini. */
struct OpenNI2Params
{
	std::string sensorLabel = "RGBD";
	/** "" = the first device found, "Dummy", or an .oni file path. */
	std::string uri;
	/** Video mode; 0 = keep the device's default. */
	int width = 0, height = 0, fps = 0;
	/** Ask the device to register depth to colour (when supported). */
	bool registerDepth = true;
	/** Horizontal field of view used when the device reports none [deg]
	 * (the Dummy device reports 0; Kinect v1 depth is about 58.5). */
	double fallbackHfovDeg = 58.5;
	/** Longest wait for a frame before grab() gives up [ms]. */
	int timeoutMs = 2000;
	double maxRangeM = 10;  ///< maxRange written in the observations [m]

	/** Reads the section strictly (driver= and unknown keys checked by the
	 * caller's ConfigSection). */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section);
};

class OpenNI2Source
{
 public:
	/** Opens the device and starts depth (and colour, when the device has
	 * it) streams. Throws std::runtime_error with OpenNI2's message when
	 * there is no device or it cannot stream: never aborts. */
	explicit OpenNI2Source(const OpenNI2Params& p);
	~OpenNI2Source();
	OpenNI2Source(const OpenNI2Source&) = delete;
	OpenNI2Source& operator=(const OpenNI2Source&) = delete;

	/** The next depth frame with the newest colour frame, stamped on the
	 * host clock; null on timeout. Throws std::runtime_error if the device
	 * is gone (unplugged) or an .oni file ended. */
	mrpt::obs::CObservation3DRangeScan::Ptr grab();

	/** "URI (vendor name), WxH depth [+ WxH colour] @ fps". */
	std::string describe() const;
	const OpenNI2Params& params() const { return p_; }

 private:
	struct Impl;
	OpenNI2Params p_;
	std::unique_ptr<Impl> d_;
};

}  // namespace bims::grab
