#include <bims/apps/run_report.h>
#include <bims/eval/mask_labels.h>
#include <bims/eval/mask_metrics.h>
#include <bims/eval/trajectory_metrics.h>
#include <bims/io/frame_files.h>
#include <bims/io/json.h>
#include <bims/io/output_paths.h>
#include <bims/io/trajectory.h>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace bims::apps
{
namespace fs = std::filesystem;
namespace ev = bims::eval;

namespace
{
std::string num(const Json& v, int decimals)
{
	if (!v.is_number()) return "n/a";
	char buf[64];
	std::snprintf(buf, sizeof buf, "%.*f", decimals, v.get<double>());
	return buf;
}

size_t count(const Json& j, const char* key)
{
	return j.contains(key) && j[key].is_number() ? j[key].get<size_t>() : 0;
}

/** "| stage | median | p95 |" rows of the stages a user reads. */
std::string stageTable(const Json& stages)
{
	std::ostringstream o;
	o << "| stage | median ms | p95 ms |\n|---|---:|---:|\n";
	for (const char* k :
	     {"read", "input", "egomotion", "flow", "grids", "outputs", "total"})
		if (stages.contains(k))
			o << "| " << k << " | " << num(stages[k]["median"], 2) << " | "
			  << num(stages[k]["p95"], 2) << " |\n";
	return o.str();
}

/** The scores against IN_gt/ (one input only), or "" when it has none. */
std::string scores(const RunReportInputs& in)
{
	if (in.rawlogs.size() != 1) return "";
	const std::string gtDir = groundTruthDirFor(in.rawlogs.front());
	std::ostringstream o;
	const std::string gtTraj = gtDir + "/groundtruth.txt";
	const std::string estTraj = in.outDir + "/trajectory.txt";
	if (fs::exists(gtTraj) && fs::exists(estTraj))
	{
		try
		{
			const auto gt = loadTumTrajectory(gtTraj);
			const auto est = loadTumTrajectory(estTraj);
			const auto ate = ev::computeAte(gt, est);
			char buf[256];
			std::snprintf(buf, sizeof buf,
			              "- trajectory against `%s`: ATE RMSE %.4f m over %zu "
			              "poses",
			              gtTraj.c_str(), ate.stats.rmse, ate.pairs.size());
			o << buf;
			try
			{
				const auto rpe = ev::computeRpe(gt, est);
				std::snprintf(buf, sizeof buf,
				              ", RPE %.4f m/s and %.3f deg/s (delta 1 s)",
				              rpe.trans.rmse, rpe.rot.rmse);
				o << buf;
			}
			catch (const std::invalid_argument&)
			{
				o << " (RPE: the run is shorter than 1 s)";
			}
			o << " (`bims-eval traj " << gtTraj << " " << estTraj << "`)\n";
		}
		catch (const std::exception& e)
		{
			o << "- trajectory: not scored (" << e.what() << ")\n";
		}
	}
	const std::string gtMasks = gtDir + "/masks";
	if (fs::is_directory(gtMasks) && fs::is_directory(in.outDir + "/masks"))
	{
		try
		{
			const auto labels = ev::listMaskFiles(gtMasks);
			const auto preds = ev::listMaskFiles(in.outDir + "/masks");
			const auto match = ev::matchMasks(labels, preds, {}, 0.01);
			const auto conv = ev::LabelConvention::explicitValues(255, 0, {});
			ev::MaskMetrics m;
			for (const auto& p : match.pairs)
				m.accumulate(
				    ev::loadMask(gtMasks + "/" + p.label->name, in.images),
				    ev::loadMask(in.outDir + "/masks/" + p.pred->name,
				                 in.images),
				    cv::Mat(), conv);
			o << "- moving masks against `" << gtMasks << "` ("
			  << match.pairs.size()
			  << " frames, every pixel): " << m.scoresLine()
			  << "; static called moving " << num(Json(m.staticAsMoving()), 4)
			  << " (over the pixels with depth: `bims-eval masks " << gtMasks
			  << " " << in.outDir << "/masks --depth-valid "
			  << in.rawlogs.front() << "`)\n";
		}
		catch (const std::exception& e)
		{
			o << "- moving masks: not scored (" << e.what() << ")\n";
		}
	}
	return o.str();
}

/** The report's head: status, variant, parameters, input. */
void reportHead(std::ostringstream& o, Json& j, const RunReportInputs& in)
{
	o << "# bims-run report\n\n";
	o << "- status: **" << j.value("status", std::string("?")) << "**";
	if (!j.value("error", std::string()).empty())
		o << " (" << j["error"].get<std::string>() << ")";
	o << "\n- variant: " << j.value("variant", std::string("?"))
	  << "; parameters: `" << in.config << "` (every value in "
	  << "[effective.ini](effective.ini))\n- input:";
	for (const auto& r : in.rawlogs) o << " `" << r << "`";
}

/** ## Frames, ## IMU and ## Speed (a figure missing from \a j: null). */
void reportRun(std::ostringstream& o, Json& j, const RunReportInputs& in)
{
	o << "\n\n## Frames\n\n";
	o << "- " << count(j, "frames_processed") << " frames of "
	  << count(j, "scans_read") << " 3D scans read, "
	  << num(j["data_seconds"], 1) << " s of data; the motion not measured on "
	  << count(j, "frames_not_measured") << "\n";
	o << "- egomotion flags (frames; docs/ego.md):";
	if (!j.contains("frames_flagged_by") || j["frames_flagged_by"].empty())
		o << " none";
	else
		for (const auto& [k, v] : j["frames_flagged_by"].items())
			o << " " << k << " " << v.get<size_t>() << ";";
	o << "\n- mean moving-pixel fraction "
	  << num(Json(100.0 * j.value("mean_moving_pixel_fraction", 0.0)), 2)
	  << " %\n";
	o << "\n## IMU\n\n- odometry mode: " << in.odometryMode << "\n- "
	  << count(j, "imu_read") << " IMU samples read, "
	  << count(j, "imu_rejected") + count(j, "imu_out_of_order") +
	         count(j, "imu_bad_stamp")
	  << " not used (out of range, out of order or a stray stamp)\n";
	if (j.contains("notes"))
		for (const auto& n : j["notes"])
			o << "- note: " << n.get<std::string>() << "\n";
	o << "\n## Speed\n\n- " << num(j["fps"], 1) << " frames/s end to end ("
	  << num(j["wall_seconds"], 1) << " s wall, " << num(j["cpu_seconds"], 1)
	  << " s CPU, peak memory " << num(j["peak_resident_mib"], 0)
	  << " MiB)\n\n";
	if (j.contains("stage_ms")) o << stageTable(j["stage_ms"]);
}

/** ## Outputs: the run folder's files, the middle frame's mask shown. */
void reportOutputs(std::ostringstream& o, const Json& j,
                   const RunReportInputs& in)
{
	o << "\n## Outputs\n\n";
	o << "- [trajectory.txt](trajectory.txt): the camera's poses (TUM)\n";
	o << "- [masks/](masks/): moving pixels per frame (255 moving)";
	std::vector<std::string> names;
	if (count(j, "frames_processed") > 0 && j.contains("frames_processed") &&
	    fs::is_directory(in.outDir + "/masks"))
		for (const auto& e : fs::directory_iterator(in.outDir + "/masks"))
			names.push_back(e.path().filename().string());
	std::sort(names.begin(), names.end());
	if (!names.empty())
	{
		const std::string mid = names[names.size() / 2];
		o << "; the middle one:\n\n  ![mask " << mid << "](masks/" << mid
		  << ")\n";
	}
	else
		o << "\n";
	for (const auto& [file, what] :
	     std::vector<std::pair<std::string, std::string>>{
	         {"frames.csv", "per-frame figures and timings"},
	         {"metrics.json", "the run's figures"},
	         {"moving_voxels/", "moving voxels per frame (PLY)"},
	         {"static_map.ply", "the static map without ghosts"},
	         {"segmented.rawlog",
	          "the masks as pixel labels of each 3D scan (read beside the "
	          "input; [output] labelled_rawlog_images copies its images)"}})
		if (fs::exists(in.outDir + "/" + file))
			o << "- [" << file << "](" << file << "): " << what << "\n";
}
}  // namespace

std::string runReport(const RunReportInputs& in)
{
	// (not const: a figure missing from it reads as null, as before)
	Json j = readJsonFile(in.outDir + "/metrics.json");
	std::ostringstream o;
	reportHead(o, j, in);
	reportRun(o, j, in);
	const std::string sc = scores(in);
	o << "\n## Scores\n\n";
	if (sc.empty())
		o << "No ground truth beside the input (IN_gt/groundtruth.txt, "
		     "IN_gt/masks/): score with `bims-eval traj` and `bims-eval masks` "
		     "(docs/eval.md).\n";
	else
		o << sc;
	reportOutputs(o, j, in);
	return o.str();
}

void writeRunReport(const RunReportInputs& in)
{
	writeFileAtomically(in.outDir + "/report.md", runReport(in));
}

}  // namespace bims::apps
