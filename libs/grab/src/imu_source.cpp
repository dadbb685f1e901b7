#include <bims/common/config.h>
#include <bims/grab/host_clock.h>
#include <bims/grab/imu_source.h>
#include <bims/io/rawlog.h>

#include <mrpt/hwdrivers/CGenericSensor.h>
#include <mrpt/hwdrivers/CIMUXSens_MT4.h>

#include <algorithm>
#include <stdexcept>

namespace bims::grab
{
namespace
{
/** MRPT's CIMUXSens_MT4 through the CGenericSensor interface. */
class XsensImuSource : public ImuSource
{
 public:
	XsensImuSource(const mrpt::config::CConfigFileBase& cfg,
	               const std::string& section)
	{
		sensor_ =
		    mrpt::hwdrivers::CGenericSensor::createSensorPtr("CIMUXSens_MT4");
		if (!sensor_)
			throw std::runtime_error(
			    "[" + section +
			    "] driver=CIMUXSens_MT4: MRPT was built without Xsens support");
		sensor_->loadConfig(cfg, section);
		try
		{
			sensor_->initialize();
		}
		catch (const std::exception& e)
		{
			// MRPT's text has a banner and a call stack: keep the message.
			std::string msg = mrpt::exception_to_str(e);
			const auto m = msg.find("Message:");
			if (m != std::string::npos)
			{
				msg = msg.substr(m + 8);
				msg = msg.substr(0, msg.find('\n'));
				while (!msg.empty() && msg.front() == ' ') msg.erase(0, 1);
			}
			throw std::runtime_error("[" + section + "] Xsens IMU: " + msg);
		}
		label_ = sensor_->getSensorLabel();
	}
	std::vector<mrpt::obs::CObservationIMU::Ptr> poll() override
	{
		sensor_->doProcess();
		mrpt::hwdrivers::CGenericSensor::TListObservations l;
		sensor_->getObservations(l);
		std::vector<mrpt::obs::CObservationIMU::Ptr> out;
		const double now = hostNow();
		for (auto& [t, o] : l)
			if (auto m =
			        std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o))
			{
				m->timestamp = mrpt::Clock::fromDouble(
				    clock_.map(mrpt::Clock::toDouble(m->timestamp), now));
				out.push_back(m);
			}
		return out;
	}
	std::string describe() const override
	{
		return "Xsens MTi (CIMUXSens_MT4), label " + label_;
	}

 private:
	mrpt::hwdrivers::CGenericSensor::Ptr sensor_;
	ClockMapper clock_;
	std::string label_;
};
}  // namespace

RawlogImuSource::RawlogImuSource(const std::string& path,
                                 const std::string& sourceLabel,
                                 const std::string& outLabel, bool loop)
    : path_(path), outLabel_(outLabel), loop_(loop)
{
	RawlogReader r(path);
	double t0 = 0;
	while (auto o = r.next())
	{
		auto m = std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o);
		if (!m || (!sourceLabel.empty() && m->sensorLabel != sourceLabel))
			continue;
		const double t = mrpt::Clock::toDouble(m->timestamp);
		if (samples_.empty()) t0 = t;
		if (!dt_.empty() && t - t0 < dt_.back()) continue;  // out of order
		samples_.push_back(m);
		dt_.push_back(t - t0);
	}
	if (samples_.size() < 2)
		throw std::runtime_error(
		    path + ": fewer than 2 IMU observations" +
		    (sourceLabel.empty() ? "" : " with label '" + sourceLabel + "'"));
	period_ = dt_.back() + dt_.back() / (dt_.size() - 1);
	start_ = hostNow();
}

std::vector<mrpt::obs::CObservationIMU::Ptr> RawlogImuSource::poll()
{
	std::vector<mrpt::obs::CObservationIMU::Ptr> out;
	const double elapsed = hostNow() - start_;
	for (;;)
	{
		if (next_ == samples_.size())
		{
			if (!loop_) break;
			next_ = 0;
			++loops_;
		}
		const double dt = dt_[next_] + loops_ * period_;
		if (dt > elapsed) break;
		auto m = std::make_shared<mrpt::obs::CObservationIMU>(*samples_[next_]);
		m->sensorLabel = outLabel_;
		m->timestamp = mrpt::Clock::fromDouble(start_ + dt);
		out.push_back(m);
		++next_;
	}
	return out;
}

std::string RawlogImuSource::describe() const
{
	return "IMU replayed from " + path_ + " (" +
	       std::to_string(samples_.size()) + " samples" +
	       (loop_ ? ", looped)" : ")");
}

std::unique_ptr<ImuSource> makeImuSource(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section,
    const std::string& driver, const std::string& iniDir)
{
	if (driver == "CIMUXSens_MT4")
		return std::make_unique<XsensImuSource>(cfg, section);
	if (driver == "RawlogImu")
	{
		ConfigSection sec(cfg, section, true);
		sec.allow("driver");
		const std::string label = sec.getString("sensorLabel", "IMU");
		std::string file = sec.requireString("file");
		const std::string src = sec.getString("source_label", "");
		const bool loop = sec.getBool("loop", true);
		sec.finish();
		if (!file.empty() && file[0] != '/' && !iniDir.empty())
			file = iniDir + "/" + file;
		return std::make_unique<RawlogImuSource>(file, src, label, loop);
	}
#ifdef BIMS_GRAB_WITH_SIM
	if (driver == "SimImu") return makeSimImuSource(cfg, section);
#endif
	throw ConfigError(configSourceName(cfg) + ": [" + section +
	                  "] driver=" + driver +
	                  ": not an IMU driver (CIMUXSens_MT4, RawlogImu"
#ifdef BIMS_GRAB_WITH_SIM
	                  ", SimImu"
#endif
	                  ")");
}

}  // namespace bims::grab
