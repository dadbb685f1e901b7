// IMU sources for live grabbing, all stamping on the host clock
// (host_clock.h): an Xsens MTi through MRPT's CIMUXSens_MT4, or the IMU
// samples of a rawlog replayed in real time (for tests and demos without
// hardware; e.g. the simulated IMU of rawlogs/pendulum_slow.rawlog).
#pragma once

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/obs/CObservationIMU.h>

#include <memory>
#include <string>
#include <vector>

namespace bims::grab
{
class ImuSource
{
 public:
	virtual ~ImuSource() = default;
	/** The samples that arrived since the last call, in time order, stamped
	 * on the host clock. Throws std::runtime_error if the device is lost. */
	virtual std::vector<mrpt::obs::CObservationIMU::Ptr> poll() = 0;
	virtual std::string describe() const = 0;
	/** The files it reads (a replayed rawlog), for the output guard. */
	virtual std::vector<std::string> inputFiles() const { return {}; }
};

/** Creates the IMU source of one grab .ini section by its driver=:
 *  - CIMUXSens_MT4: MRPT's driver; the section is passed to its
 *    loadConfig() (keys: sensorLabel, portname_LIN, baudRate, deviceId,
 *    sampleFreq, pose_*). Throws when no device is found.
 *  - RawlogImu: keys sensorLabel (default IMU), file (a rawlog; relative
 *    paths are relative to the .ini's folder), source_label (the IMU label
 *    in that file, "" = any), loop (default true).
 *  - SimImu (when libs/sim is built): the simulator's noisy IMU sampled in
 *    real time; keys sensorLabel (IMU), rate_hz (100), moving (false: the
 *    camera at rest; true: libs/sim's default hand-held motion), seed (1).
 * \param iniDir folder of the .ini (for relative paths). */
std::unique_ptr<ImuSource> makeImuSource(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section,
    const std::string& driver, const std::string& iniDir);

/** driver=SimImu (only when built with libs/sim). */
std::unique_ptr<ImuSource> makeSimImuSource(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section);

/** Replays the IMU samples of a rawlog in real time from construction on:
 * a sample recorded dt after the first one is released dt after start,
 * stamped start + dt on the host clock. */
class RawlogImuSource : public ImuSource
{
 public:
	RawlogImuSource(const std::string& path, const std::string& sourceLabel,
	                const std::string& outLabel, bool loop);
	std::vector<mrpt::obs::CObservationIMU::Ptr> poll() override;
	std::string describe() const override;
	std::vector<std::string> inputFiles() const override { return {path_}; }
	size_t samplesInFile() const { return samples_.size(); }

 private:
	std::string path_, outLabel_;
	bool loop_;
	std::vector<mrpt::obs::CObservationIMU::Ptr> samples_;
	std::vector<double> dt_;  ///< time after the first sample [s]
	double period_ = 0;       ///< one loop [s]
	double start_ = 0;
	size_t next_ = 0, loops_ = 0;
};

}  // namespace bims::grab
