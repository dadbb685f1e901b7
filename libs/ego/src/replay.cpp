#include <bims/common/frame_files.h>
#include <bims/common/imu_check.h>
#include <bims/common/progress.h>
#include <bims/common/rawlog.h>
#include <bims/ego/depth_correction.h>
#include <bims/ego/flags.h>
#include <bims/ego/replay.h>

#include <mrpt/core/Clock.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <deque>
#include <filesystem>
#include <limits>
#include <stdexcept>

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
	// scans waiting for the IMU, with their index among the 3D scans
	std::deque<std::pair<CObservation3DRangeScan::Ptr, long>> pending;
	long nScans = 0;
	cv::Mat mask;
	RejectedImuSamples rejectedImu;  // as bims-run
	DepthCorrection depthCorrection(cfg.depth_correction);
	ProgressBar bar("bims-odom", 0, opt.progress);
	bool done = false;

	const auto process = [&](const CObservation3DRangeScan::Ptr& o, long k)
	{
		o->load();
		mask.release();
		if (!opt.masks_dir.empty() && k > 0)
		{
			const std::string mp = opt.masks_dir + "/" + frameFileName(k - 1);
			if (std::filesystem::exists(mp))
			{
				mask = cv::imread(mp, cv::IMREAD_UNCHANGED);
				if (mask.type() != CV_8UC1 ||
				    mask.cols != static_cast<int>(o->rangeImage.cols()) ||
				    mask.rows != static_cast<int>(o->rangeImage.rows()))
					throw std::runtime_error(
					    mp + ": not an 8-bit mask of the depth image's size (" +
					    std::to_string(o->rangeImage.cols()) + "x" +
					    std::to_string(o->rangeImage.rows()) + ")");
				++st.masksUsed;
			}
		}
		FrameEgomotion r = odo.processFrame(*o, mask.empty() ? nullptr : &mask);
		if (rejectedImu.upTo(r.t + offset)) r.flags |= kFlagImuRejected;
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
			const double t =
			    mrpt::Clock::toDouble(pending.front().first->timestamp);
			if (!all && t + offset > lastImuT && newestT - t <= opt.imu_wait_s)
				break;
			process(pending.front().first, pending.front().second);
			pending.pop_front();
		}
	};

	RawlogReader reader(path);
	// the total: max_frames, or estimated from the share of the input read
	const uint64_t inputBytes = rawlogDataBytes(path);
	if (opt.max_frames) bar.setTotal(opt.max_frames);
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
			if (!rejectedImu
			         .check(*imu, t, "bims-odom", path,
			                reader.observationsRead() - 1)
			         .empty())
			{
				st.imuRejected = rejectedImu.count();
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
			pending.emplace_back(scan, nScans++);
			if (!opt.max_frames && inputBytes > 0 && reader.bytesRead() > 0)
				bar.setTotal(
				    static_cast<size_t>(
				        double(nScans) * inputBytes / reader.bytesRead() + 0.5),
				    true);
		}
		newestT = std::max(newestT, t);
		flush(false);
	}
	flush(true);
	bar.finish();
	return st;
}

}  // namespace bims::ego
