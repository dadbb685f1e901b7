#include "outputs.h"
#include <bims/common/clock.h>
#include <bims/io/frame_files.h>
#include <bims/io/json.h>
#include <bims/io/output_paths.h>

#include <bims/common/cpu_time.h>

#include <bims/ego/flags.h>
#include <bims/io/pixel_labels.h>
#include <bims/io/trajectory.h>
#include <bims/maps/export.h>
#include <mrpt/obs/TPixelLabelInfo.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <initializer_list>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

namespace bims::pipeline
{
using Clock = std::chrono::steady_clock;

void writePointsPly(const std::string& path,
                    const std::vector<mrpt::math::TPoint3D>& pts)
{
	std::string text = "ply\nformat ascii 1.0\nelement vertex " +
	                   std::to_string(pts.size()) +
	                   "\nproperty float x\nproperty float y\nproperty float "
	                   "z\nend_header\n";
	text.reserve(text.size() + 32 * pts.size());
	char buf[96];
	for (const auto& p : pts)
	{
		std::snprintf(buf, sizeof(buf), "%.4f %.4f %.4f\n", p.x, p.y, p.z);
		text += buf;
	}
	writeFileAtomically(path, text);
}

namespace
{
/** Queue length of the writer: a few frames, so a slow disk slows the run
 * down instead of filling the memory (about 2 MB per VGA frame). */
constexpr size_t kQueuedWrites = 16;
}  // namespace

const OutputFolderLayout& runOutputLayout()
{
	// every name a run writes (OutputWriter, effective.ini; the test of
	// bims-run's --overwrite checks that a run leaves nothing else)
	static const OutputFolderLayout layout{
	    {"trajectory.txt", "frames.csv", "metrics.json", "effective.ini",
	     "segmented.rawlog", "static_map.ply", "static_map.bt",
	     "report.md"},  // (report.md: bims-run's, bims/apps/run_report.h)
	    {{"masks", ".png"},
	     {"moving_voxels", ".ply"},
	     {"flow_labels", ".png"}}};
	return layout;
}

OutputWriter::OutputWriter(const std::string& dir, const OutputParams& p,
                           const std::vector<std::string>& laterFiles)
    : dir_(dir), p_(p), worker_(kQueuedWrites, p.writer_thread)
{
	makeDirs(dir_);
	manifest_ = std::make_unique<OutputManifest>(dir_, "bims-run");
	for (const auto& f : laterFiles) manifest_->file(f);
	makeDirs(dir_ + "/masks");
	// written last: a folder without it is partial (an earlier run's would
	// say otherwise)
	if (std::remove((dir_ + "/metrics.json").c_str()) != 0 && errno != ENOENT)
		throw std::runtime_error(
		    dir_ + "/metrics.json: cannot remove: " + std::strerror(errno));
	if (p_.moving_ply) makeDirs(dir_ + "/moving_voxels");
	if (p_.flow_labels) makeDirs(dir_ + "/flow_labels");
	// grown line by line, each line checked and whole
	traj_ = std::make_unique<AppendFile>(file("trajectory.txt"));
	csv_ = std::make_unique<AppendFile>(file("frames.csv"));
	traj_->append(
	    tumHeader("bims-run estimated camera trajectory T_WC (optical frame)"));
	csv_->append(
	    "index,t,ego_flags,correspondences,inliers,residual_m,hit_voxels,"
	    "moving_voxels,moving_px,diff_px,notdiff_px,"
	    "ms_input,ms_ego,ms_flow,ms_grids,ms_total,filled_px,degenerate_dirs,"
	    "held,ego_flag_names\n");
	if (p_.labelled_rawlog)
		rawlog_ = std::make_unique<RawlogWriter>(file("segmented.rawlog"),
		                                         p_.labelled_rawlog_gz_level);
}

double OutputWriter::writeFrame(const FrameResult& r,
                                mrpt::obs::CObservation3DRangeScan::Ptr scan,
                                uint32_t flags)
{
	// What the writer needs, in buffers of its own (the pipeline keeps the
	// mask as its feedback).
	auto c = std::make_shared<FrameResult>(r);
	c->maskTier1 = c->maskTier2 = c->maskFlow = cv::Mat();
	c->flowObserved = c->flowExpected = cv::Mat();
	c->ego.flags = flags;
	c->mask = r.mask.clone();
	c->labels = p_.flow_labels ? r.labels.clone() : cv::Mat();
	return worker_.post(
	    [this, c, scan]
	    {
		    const auto t0 = Clock::now();
		    const double cpu0 = threadCpuMs();
		    doWriteFrame(*c, *scan);
		    frameCpuMs_.push_back(otherCpuMs_ + threadCpuMs() - cpu0);
		    frameMs_.push_back(otherMs_ + msSince(t0));
		    otherMs_ = otherCpuMs_ = 0;
	    });
}

void OutputWriter::doWriteFrame(const FrameResult& r,
                                mrpt::obs::CObservation3DRangeScan& scan)
{
	writeImageFile(file("masks/" + frameFileName(long(r.index))), r.mask);
	if (p_.moving_ply)
		writePointsPly(
		    file("moving_voxels/" + frameFileName(long(r.index), "ply")),
		    r.movingVoxelCentres);
	if (p_.flow_labels && !r.labels.empty())
	{
		cv::Mat vis(r.labels.size(), CV_8UC1, cv::Scalar(0));
		vis.setTo(128, r.labels == 0);
		vis.setTo(255, r.labels == 1);
		writeImageFile(file("flow_labels/" + frameFileName(long(r.index))),
		               vis);
	}
	if (rawlog_)
	{
		// Label 0 ("moving"), bit 0 of each pixel's byte; written in one
		// buffer (MRPT's TPixelLabelInfo<1> bytes, ~3 ms less per VGA frame).
		auto labels = bims::BulkPixelLabels::fromMask(r.mask.ptr<uint8_t>(0),
		                                              r.mask.rows, r.mask.cols,
		                                              r.mask.step[0], "moving");
		if (p_.labelled_rawlog_images)
		{
			scan.pixelLabels = labels;  // no copy of the images
			rawlog_->write(scan);
		}
		else
		{
			// the scan without its images: what finds it in the input (stamp,
			// sensor label) and reads its pixels (cameras, poses), the labels
			mrpt::obs::CObservation3DRangeScan lab;
			lab.timestamp = scan.timestamp;
			lab.sensorLabel = scan.sensorLabel;
			lab.sensorPose = scan.sensorPose;
			lab.cameraParams = scan.cameraParams;
			lab.cameraParamsIntensity = scan.cameraParamsIntensity;
			lab.relativePoseIntensityWRTDepth =
			    scan.relativePoseIntensityWRTDepth;
			lab.rangeUnits = scan.rangeUnits;
			lab.maxRange = scan.maxRange;
			lab.stdError = scan.stdError;
			lab.pixelLabels = labels;
			rawlog_->write(lab);
		}
		// a killed run leaves it readable up to the last whole frame
		rawlog_->flush();
	}
	// the trajectory and frames.csv last: a frame in frames.csv is in every
	// output
	traj_->append(tumLine(r.t, r.T_WC) + "\n");
	char buf[512];
	std::snprintf(buf, sizeof(buf),
	              "%zu,%.6f,%u,%d,%d,%.5f,%zu,%zu,%d,%zu,%zu,%.3f,%.3f,%.3f,%."
	              "3f,%.3f,%d,%d,%d,%s\n",
	              r.index, r.t, r.ego.flags, r.ego.correspondences,
	              r.ego.inliers, r.ego.residual_rms_m, r.hitVoxels,
	              r.movingVoxels, cv::countNonZero(r.mask), r.labelStats.diff,
	              r.labelStats.notDiff, r.ms.input, r.ms.egomotion, r.ms.flow,
	              r.ms.grids, r.ms.total, r.surfaceFill.added,
	              std::max(0, r.ego.degenerate), r.held ? 1 : 0,
	              ego::flagsToString(r.ego.flags).c_str());
	csv_->append(buf);
}

double OutputWriter::writeOther(mrpt::obs::CObservation::Ptr obs)
{
	if (!rawlog_) return 0;
	return worker_.post(
	    [this, obs]
	    {
		    const auto t0 = Clock::now();
		    const double cpu0 = threadCpuMs();
		    rawlog_->write(*obs);
		    otherCpuMs_ += threadCpuMs() - cpu0;
		    otherMs_ += msSince(t0);
	    });
}

size_t OutputWriter::close(Pipeline& pipe)
{
	std::string err;
	try
	{
		worker_.drain();
	}
	catch (const std::exception& e)
	{
		err = e.what();
	}
	// every file closed, the first error kept
	for (const auto& closeOne :
	     std::initializer_list<std::function<void()>>{[&] { traj_->close(); },
	                                                  [&] { csv_->close(); },
	                                                  [&]
	                                                  {
		                                                  if (rawlog_)
			                                                  rawlog_->close();
	                                                  }})
	{
		try
		{
			closeOne();
		}
		catch (const std::exception& e)
		{
			if (err.empty()) err = e.what();
		}
	}
	size_t nStatic = 0;
	const auto& g = pipe.grids();
	const maps::CMotionGridBase* motion = pipe.maskGrid();
	if (p_.static_map && pipe.framesProcessed() > 0)
	{
		PartialFile ply(file("static_map.ply")), bt(file("static_map.bt"));
		nStatic = maps::writeStaticPly(ply.path(), *g.occupancy(), motion,
		                               p_.static_p_occupied);
		maps::writeStaticOctomap(bt.path(), *g.occupancy(), motion,
		                         p_.static_p_occupied);
		ply.commit();
		bt.commit();
	}
	staticVoxels_ = nStatic;
	if (!err.empty()) throw std::runtime_error(err);
	return nStatic;
}

namespace
{
/** What a field of metrics.json is made from. */
struct MetricInputs
{
	const Pipeline& pipe;
	const RunSummary& sum;
	size_t staticVoxels;
};

/** What a field holds: a number (a metric), text, one number per stage
 * (median, p95, mean, n) or per egomotion flag, or a list. */
enum class MetricKind
{
	Number,
	Text,
	PerStage,
	PerFlag,
	List
};

struct MetricField
{
	const char* key;
	MetricKind kind;
	Json (*value)(const MetricInputs&);
};

/** metrics.json's fields in their order: the one list of its keys, which
 * the writer writes and metricNames() names. */
const std::vector<MetricField>& metricFields()
{
	using K = MetricKind;
	using M = const MetricInputs&;
	static const std::vector<MetricField> fields = {
	    {"status", K::Text, [](M m) { return Json(m.sum.status()); }},
	    {"variant", K::Text, [](M m) { return Json(m.sum.variant); }},
	    {"config", K::Text, [](M m) { return Json(m.pipe.config().source); }},
	    {"frames_processed", K::Number,
	     [](M m) { return Json(m.sum.framesProcessed); }},
	    {"frames_flagged", K::Number,
	     [](M m) { return Json(m.sum.framesFlagged); }},
	    {"frames_not_measured", K::Number,
	     [](M m) { return Json(m.sum.framesNotMeasured); }},
	    {"frames_flagged_by", K::PerFlag,
	     [](M m) { return Json(m.sum.framesFlaggedBy); }},
	    {"notes", K::List, [](M m) { return Json(m.sum.notes); }},
	    {"scans_read", K::Number, [](M m) { return Json(m.sum.scansRead); }},
	    {"imu_read", K::Number, [](M m) { return Json(m.sum.imuRead); }},
	    {"scans_out_of_order", K::Number,
	     [](M m) { return Json(m.sum.scansOutOfOrder); }},
	    {"wall_seconds", K::Number,
	     [](M m) { return jsonNumber(m.sum.seconds, 3); }},
	    {"cpu_seconds", K::Number,
	     [](M m) { return jsonNumber(m.sum.cpuSeconds, 3); }},
	    {"peak_resident_mib", K::Number,
	     [](M m) { return jsonNumber(m.sum.peakResidentMiB, 1); }},
	    {"fps", K::Number, [](M m) { return jsonNumber(m.sum.fps(), 3); }},
	    {"data_seconds", K::Number,
	     [](M m) { return jsonNumber(m.sum.dataSeconds, 3); }},
	    {"mean_moving_pixel_fraction", K::Number,
	     [](M m) { return jsonNumber(m.sum.meanMovingPixelFraction, 6); }},
	    {"static_map_voxels", K::Number,
	     [](M m) { return Json(m.staticVoxels); }},
	    {"frames_flow_ahead", K::Number,
	     [](M m) { return Json(m.sum.framesFlowAhead); }},
	    {"frames_without_flow", K::Number,
	     [](M m) { return Json(m.sum.framesWithoutFlow); }},
	    {"frames_surface_filled", K::Number,
	     [](M m) { return Json(m.sum.framesSurfaceFilled); }},
	    {"pixels_surface_filled", K::Number,
	     [](M m) { return Json(m.sum.pixelsSurfaceFilled); }},
	    {"frames_held", K::Number, [](M m) { return Json(m.sum.framesHeld); }},
	    {"frames_without_imu", K::Number,
	     [](M m) { return Json(m.sum.framesWithoutImu); }},
	    {"imu_rejected", K::Number,
	     [](M m) { return Json(m.sum.imuRejected); }},
	    {"imu_out_of_order", K::Number,
	     [](M m) { return Json(m.sum.imuOutOfOrder); }},
	    {"imu_bad_stamp", K::Number,
	     [](M m) { return Json(m.sum.imuBadStamp); }},
	    {"scans_bad_stamp", K::Number,
	     [](M m) { return Json(m.sum.scansBadStamp); }},
	    {"stage_ms", K::PerStage,
	     [](M m)
	     {
		     Json stages = Json::object();
		     for (const auto& [name, p] : m.sum.stageMs)
			     stages[name] = {{"median", jsonNumber(p.median, 3)},
			                     {"p95", jsonNumber(p.p95, 3)},
			                     {"mean", jsonNumber(p.mean, 3)},
			                     {"n", p.n}};
		     return stages;
	     }},
	    {"error", K::Text, [](M m) { return Json(m.sum.error); }}};
	return fields;
}
}  // namespace

const std::vector<std::string>& stageNames()
{
	// in the summary's order
	static const std::vector<std::string> names = {
	    "read",  "read_cpu",      "wait_input", "input",       "egomotion",
	    "flow",  "flow_observed", "grids",      "grids_cloud", "grids_decay",
	    "total", "total_cpu",     "outputs",    "outputs_cpu", "wait_output"};
	return names;
}

std::vector<std::string> metricNames()
{
	std::vector<std::string> names;
	for (const auto& f : metricFields())
		if (f.kind == MetricKind::Number)
			names.push_back(f.key);
		else if (f.kind == MetricKind::PerFlag)
			for (const char* flag :
			     ego::flagNames(~uint32_t(ego::kFlagFirstFrame)))
				names.push_back(std::string(f.key) + "." + flag);
		else if (f.kind == MetricKind::PerStage)
			for (const auto& stage : stageNames())
				for (const char* stat : {"median", "p95", "mean", "n"})
					names.push_back(std::string(f.key) + "." + stage + "." +
					                stat);
	return names;
}

void OutputWriter::writeMetrics(const Pipeline& pipe, const RunSummary& sum)
{
	Json j;
	const MetricInputs in{pipe, sum, staticVoxels_};
	for (const auto& f : metricFields()) j[f.key] = f.value(in);
	writeJsonFile(file("metrics.json"), j);
}

}  // namespace bims::pipeline
