#include <bims/common/progress.h>
#include <bims/common/rawlog.h>
#include <bims/ego/depth_correction.h>
#include <bims/ego/flags.h>
#include <bims/ego/replay.h>

#include <mrpt/core/Clock.h>

#include <deque>
#include <limits>

namespace bims::ego
{
ReplayStats replayRawlog(const std::string& path, Odometry& odo,
                         const FrameCallback& onFrame, const ReplayOptions& opt,
                         const ImuCallback& onImu)
{
	using mrpt::obs::CObservation3DRangeScan;
	using mrpt::obs::CObservationIMU;
	ReplayStats st;
	const auto& cfg = odo.config();
	const double offset = cfg.calibration.time_offset_s;
	double lastImuT = -std::numeric_limits<double>::infinity();
	double newestT = lastImuT;
	std::deque<CObservation3DRangeScan::Ptr> pending;
	DepthCorrection depthCorrection(cfg.depth_correction);
	ProgressBar bar("bims-odom", 0, opt.progress);
	bool done = false;

	const auto process = [&](const CObservation3DRangeScan::Ptr& o)
	{
		o->load();
		const FrameEgomotion r = odo.processFrame(*o);
		++st.frames;
		if (!r.ok() && !(r.flags & kFlagFirstFrame)) ++st.flagged;
		if (onFrame) onFrame(r, *o);
		bar.update(st.frames);
		if (opt.max_frames && st.frames >= opt.max_frames) done = true;
	};
	const auto flush = [&](bool all)
	{
		while (!pending.empty() && !done)
		{
			const double t = mrpt::Clock::toDouble(pending.front()->timestamp);
			if (!all && t + offset > lastImuT && newestT - t <= opt.imu_wait_s)
				break;
			process(pending.front());
			pending.pop_front();
		}
	};

	RawlogReader reader(path);
	while (!done)
	{
		auto o = reader.next();
		if (!o) break;
		const double t = mrpt::Clock::toDouble(o->timestamp);
		if (auto imu = std::dynamic_pointer_cast<CObservationIMU>(o))
		{
			if (!cfg.sensors.imu_label.empty() &&
			    imu->sensorLabel != cfg.sensors.imu_label)
			{
				++st.otherLabel;
				continue;
			}
			const ImuSample s = imuSampleFrom(*imu);
			odo.addImu(s);
			if (onImu) onImu(s);
			++st.imu;
			lastImuT = std::max(lastImuT, t);
		}
		else if (auto scan =
		             std::dynamic_pointer_cast<CObservation3DRangeScan>(o))
		{
			if (!cfg.sensors.rgbd_label.empty() &&
			    scan->sensorLabel != cfg.sensors.rgbd_label)
			{
				++st.otherLabel;
				continue;
			}
			depthCorrection.apply(*scan, cfg.camera);
			pending.push_back(scan);
		}
		newestT = std::max(newestT, t);
		flush(false);
	}
	flush(true);
	bar.finish();
	return st;
}

}  // namespace bims::ego
