#include <bims/common/config.h>
#include <bims/grab/grabber.h>
#include <bims/grab/host_clock.h>

#include <mrpt/system/filesystem.h>

#include <algorithm>
#include <chrono>

namespace bims::grab
{
Grabber::Grabber(const mrpt::config::CConfigFileBase& cfg)
{
	const std::string file = configSourceName(cfg);
	const std::string iniDir = file.empty() || file[0] == '<'
	                               ? std::string()
	                               : mrpt::system::extractFileDirectory(file);
	std::vector<std::string> sections;
	cfg.getAllSections(sections);
	{
		ConfigSection g(cfg, "global");
		global_.maxFrames =
		    static_cast<size_t>(g.getInt("max_frames", 0, 0, 1000000000));
		global_.stallTimeoutS =
		    g.getDouble("stall_timeout_s", global_.stallTimeoutS, 0.1, 3600);
		g.finish();
	}
	for (const auto& s : sections)
	{
		if (s == "global") continue;
		const std::string driver = cfg.read_string(s, "driver", "");
		if (driver.empty())
			throw ConfigError(file + ": [" + s +
			                  "] has no driver= (every section but [global] "
			                  "is a sensor, as in rawlog-grabber)");
		if (driver == "OpenNI2")
		{
			if (rgbd_)
				throw ConfigError(file + ": [" + s +
				                  "]: only one driver=OpenNI2 section is "
				                  "supported");
			OpenNI2Params p;
			p.loadFromConfigFile(cfg, s);
			rgbd_ = std::make_unique<OpenNI2Source>(p);
		}
		else if (driver == "COpenNI2Sensor")
			throw ConfigError(
			    file + ": [" + s +
			    "] driver=COpenNI2Sensor: use driver=OpenNI2 (our source; "
			    "MRPT's COpenNI2Sensor aborts without a device and cannot "
			    "open Dummy or .oni devices)");
		else
			imus_.push_back(makeImuSource(cfg, s, driver, iniDir));
	}
	if (!rgbd_)
		throw ConfigError(file +
		                  ": no RGB-D sensor (a section with driver=OpenNI2)");
}

Grabber::~Grabber() = default;

std::vector<std::string> Grabber::describe() const
{
	std::vector<std::string> out{"RGB-D: " + rgbd_->describe()};
	for (const auto& i : imus_) out.push_back("IMU: " + i->describe());
	return out;
}

std::vector<std::string> Grabber::inputFiles() const
{
	std::vector<std::string> files;
	for (const auto& i : imus_)
		for (auto& f : i->inputFiles()) files.push_back(std::move(f));
	return files;
}

GrabStats Grabber::run(RawlogWriter& out, const std::atomic<bool>& stop,
                       size_t maxFrames, const GrabCallback& cb)
{
	using Clock = std::chrono::steady_clock;
	const auto t0 = Clock::now();
	if (maxFrames == 0) maxFrames = global_.maxFrames;
	GrabStats st;
	std::vector<mrpt::obs::CObservationIMU::Ptr> pending;  // time order
	double lastWritten = -1e300;
	auto lastFrame = Clock::now();

	auto write = [&](const mrpt::obs::CObservation& o)
	{
		const double t = mrpt::Clock::toDouble(o.timestamp);
		if (t < lastWritten) ++st.nonMonotonic;
		lastWritten = std::max(lastWritten, t);
		out.write(o);
	};
	auto pollImu = [&]()
	{
		for (auto& src : imus_)
			for (auto& m : src->poll()) pending.push_back(m);
		std::stable_sort(pending.begin(), pending.end(),
		                 [](const auto& a, const auto& b)
		                 { return a->timestamp < b->timestamp; });
	};

	try
	{
		while (!stop)
		{
			if (maxFrames > 0 && st.frames >= maxFrames)
			{
				st.stopReason = "max_frames";
				break;
			}
			auto scan = rgbd_->grab();
			pollImu();
			if (!scan)
			{
				++st.timeouts;
				const double idle =
				    std::chrono::duration<double>(Clock::now() - lastFrame)
				        .count();
				if (idle > global_.stallTimeoutS)
				{
					st.stopReason = "no RGB-D frame for " +
					                std::to_string(idle) +
					                " s (device unplugged or file ended)";
					break;
				}
				continue;
			}
			lastFrame = Clock::now();
			// IMU samples up to the frame's stamp go first.
			std::vector<mrpt::obs::CObservationIMU::Ptr> before;
			auto it = pending.begin();
			while (it != pending.end() && (*it)->timestamp <= scan->timestamp)
				before.push_back(*it++);
			pending.erase(pending.begin(), it);
			for (const auto& m : before) write(*m);
			write(*scan);
			out.flush();
			st.imu += before.size();
			++st.frames;
			if (cb) cb(scan, before);
		}
		if (stop && st.stopReason.empty()) st.stopReason = "stopped";
	}
	catch (const std::exception& e)
	{
		st.stopReason = e.what();
	}
	// Whatever IMU is left (stamped before now) still belongs to the log.
	for (const auto& m : pending) write(*m);
	st.imu += pending.size();
	out.flush();
	st.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
	return st;
}

}  // namespace bims::grab
