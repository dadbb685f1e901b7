#include <bims/apps/odometry_replay.h>
#include <bims/apps/progress_bar.h>
#include <bims/apps/warnings.h>
#include <bims/ego/flags.h>
#include <bims/io/frame_files.h>
#include <bims/io/image_file.h>
#include <bims/io/rawlog.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

namespace bims::apps
{
namespace
{
/** Scan k-1's mask of \a dir for frame \a k (empty when none). */
cv::Mat feedbackMask(const std::string& dir, const source::SourceFrame& f)
{
	if (dir.empty() || f.index == 0) return {};
	const std::string p = dir + "/" + frameFileName(f.index - 1);
	if (!std::filesystem::exists(p)) return {};
	// a mask is the depth image's size: a file declaring more is refused
	// before it is decoded
	const auto& depth = f.scan->rangeImage;
	const long w = static_cast<long>(depth.cols()),
	           h = static_cast<long>(depth.rows());
	cv::Mat mask = readImageFile(
	    p, cv::IMREAD_UNCHANGED, "mask",
	    ImageLimits{std::max(w, h), w * h, "the depth image's size"});
	if (mask.type() != CV_8UC1 || mask.cols != static_cast<int>(depth.cols()) ||
	    mask.rows != static_cast<int>(depth.rows()))
		throw std::runtime_error(
		    p + ": not an 8-bit mask of the depth image's size (" +
		    std::to_string(depth.cols()) + "x" + std::to_string(depth.rows()) +
		    ")");
	return mask;
}
}  // namespace

ReplayStats replayRawlog(const std::string& path, ego::Odometry& odo,
                         const FrameCallback& onFrame, const ReplayOptions& opt,
                         const ImuCallback& onImu)
{
	ReplayStats st;
	source::FrameOrderParams order =
	    source::FrameOrderParams::of(odo.config(), opt.imu_wait_s, "bims-odom");
	order.warn = stderrWarnings("bims-odom");
	source::RawlogFrameSource src({path}, order, false);
	ProgressBar bar("bims-odom", opt.max_frames, opt.progress);
	while (!opt.max_frames || st.frames < opt.max_frames)
	{
		auto f = src.next();
		if (!f) break;
		for (const auto& m : f->imu)
		{
			const sensors::ImuSample s = sensors::imuSampleFrom(*m);
			odo.addImu(s);
			if (onImu) onImu(s);
			++st.imu;
		}
		const cv::Mat mask = feedbackMask(opt.masks_dir, *f);
		if (!mask.empty()) ++st.masksUsed;
		ego::FrameEgomotion r =
		    odo.processFrame(*f->scan, mask.empty() ? nullptr : &mask);
		if (f->imuRejected) r.flags |= ego::kFlagImuRejected;
		++st.frames;
		if (!r.ok() && !(r.flags & ego::kFlagFirstFrame)) ++st.flagged;
		if (onFrame) onFrame(r, *f->scan);
		if (!opt.max_frames && f->inputFraction > 0)
			bar.setTotal(
			    static_cast<size_t>((f->index + 1) / f->inputFraction + 0.5),
			    true);
		bar.update(st.frames);
	}
	bar.finish();
	st.otherLabel = src.stats().otherSkipped;
	st.imuRejected = src.stats().imuRejected;
	st.imuNotes = source::imuNotes(src.stats(), odo.config().sensors.imu_label);
	if (!src.error().empty()) throw RawlogError(src.error());
	return st;
}

}  // namespace bims::apps
