#include <bims/apps/app.h>
#include <bims/apps/flow_check.h>
#include <bims/apps/frame_range_option.h>
#include <bims/apps/output_checks.h>
#include <bims/apps/progress_bar.h>
#include <bims/ego/rgbd_input.h>
#include <bims/eval/plots.h>
#include <bims/eval/pose_utils.h>
#include <bims/io/output_paths.h>
#include <bims/io/trajectory.h>
#include <bims/pipeline/mask_overlay.h>
#include <bims/pipeline/run.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace bims::apps
{
using flow::PoseSourceCheck;
using mrpt::poses::CPose3D;

const char* tableHeader()
{
	return "# index flags | Diff% ego used gt flow | median px ego used gt "
	       "flow | rot deg ego-gt ego-flow gt-flow used-flow | t mm ego-gt "
	       "ego-flow gt-flow used-flow | gt motion deg mm | Diff share on "
	       "depth edges (used)\n";
}

std::string tableLine(size_t index, uint32_t flags, const PoseSourceCheck& c)
{
	const auto& v = c.values;
	char b[512];
	std::snprintf(b, sizeof(b),
	              "%4zu %4u | %5.1f %5.1f %5.1f %5.1f | %5.2f %5.2f %5.2f "
	              "%5.2f | %5.2f %5.2f %5.2f %5.2f | %5.1f %5.1f %5.1f %5.1f | "
	              "%5.2f %5.1f | %4.2f\n",
	              index, flags, v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7],
	              v[8], v[9], v[10], v[11], v[12], v[13], v[14], v[15], v[16],
	              v[17], v[18]);
	return b;
}

const char* csvHeader()
{
	return "index,flags,valid_px,diff_ego,diff_used,diff_gt,diff_flow,px_ego,"
	       "px_used,px_gt,px_flow,rot_ego_gt_deg,rot_ego_flow_deg,"
	       "rot_gt_flow_deg,rot_used_flow_deg,t_ego_gt_mm,t_ego_flow_mm,"
	       "t_gt_flow_mm,t_used_flow_mm,gt_rot_deg,gt_t_mm,edge_share_used\n";
}

std::string csvLine(size_t index, uint32_t flags, const PoseSourceCheck& c)
{
	std::ostringstream line;
	line << index << "," << flags << "," << c.validPx;
	for (double x : c.values) line << "," << x;
	line << "\n";
	return line.str();
}

std::string summary(
    const std::vector<std::array<double, PoseSourceCheck::kValues>>& rows)
{
	std::string out;
	char b[128];
	std::snprintf(b, sizeof(b), "# mean over %zu frames:\n", rows.size());
	out += b;
	for (size_t k = 0; k < PoseSourceCheck::kValues; k++)
	{
		std::vector<double> v;
		for (const auto& r : rows) v.push_back(r[k]);
		double m = 0;
		for (double x : v) m += x;
		std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
		std::snprintf(b, sizeof(b), "%-18s mean %8.3f median %8.3f\n",
		              PoseSourceCheck::names()[k], m / v.size(),
		              v[v.size() / 2]);
		out += b;
	}
	return out;
}

cv::Mat stripTile(const mrpt::obs::CObservation3DRangeScan& scan,
                  const cv::Mat& grey, const cv::Mat& mask, size_t index)
{
	cv::Mat rgb;
	cv::cvtColor(grey, rgb, cv::COLOR_GRAY2BGR);
	if (scan.hasIntensityImage)
	{
		const cv::Mat c = scan.intensityImage.asCvMatRef();
		if (c.channels() == 3 && c.size() == rgb.size()) rgb = c.clone();
	}
	rgb = pipeline::overlayMoving(rgb, mask);
	cv::putText(rgb, "frame " + std::to_string(index), {10, 30},
	            cv::FONT_HERSHEY_SIMPLEX, 0.9, cv::Scalar(255, 255, 255), 2);
	return rgb;
}

namespace
{
/** The experiment of --config with --variant. */
pipeline::ExperimentConfig flowCheckConfig(const FlowCheckOptions& o)
{
	pipeline::ExperimentConfig cfg;
	cfg.loadFromFile(o.config);
	try
	{
		cfg.setVariant(parseChoice<pipeline::Variant>(o.variant));
	}
	catch (const std::invalid_argument& e)
	{
		throw UsageError(std::string("--variant: ") + e.what());
	}
	return cfg;
}

/** --strip: the frames' tiles side by side. */
void writeStrip(const std::string& path, const std::map<size_t, cv::Mat>& tiles)
{
	if (tiles.empty())
		throw std::runtime_error("--strip: none of the frames ran");
	std::vector<cv::Mat> strip;
	for (auto& [i, m] : tiles) strip.push_back(m);
	eval::writePng(path, eval::imageStrip(strip, 0.5));
	std::printf("strip: %s (%zu frames)\n", path.c_str(), tiles.size());
}
}  // namespace

int runFlowCheck(const FlowCheckOptions& o)
{
	std::vector<std::string> outputs;
	if (o.csv) outputs.push_back(*o.csv);
	if (o.strip) outputs.push_back(*o.strip);
	checkOutputsSpareInputs({o.config, o.rawlog, o.gt}, outputs);

	const pipeline::ExperimentConfig cfg = flowCheckConfig(o);
	const Trajectory gt = loadTumTrajectory(o.gt);
	const auto stripFrames = parseIndexList(o.stripFrames, "--strip-frames");
	if (o.strip && stripFrames.empty())
		throw UsageError("--strip needs --strip-frames");
	std::map<size_t, cv::Mat> tiles;

	pipeline::RunOptions opt;
	opt.rawlogs = {o.rawlog};
	ProgressBar bar("bims-run", 0, o.progress);  // runExperiment's line
	opt.progress = bar.callback();
	opt.frames =
	    frameRangeOption(o.frames, opt.rawlogs, cfg.ego.sensors.rgbd_label);
	std::unique_ptr<AppendFile> csv;  // each line checked
	if (o.csv)
	{
		csv = std::make_unique<AppendFile>(*o.csv);
		csv->append(csvHeader());
	}
	std::fputs(tableHeader(), stdout);
	std::optional<CPose3D> gtPrev;
	std::vector<std::array<double, PoseSourceCheck::kValues>> rows;
	opt.onFrame = [&](const pipeline::FrameResult& r,
	                  const mrpt::obs::CObservation3DRangeScan& scan)
	{
		const auto gtCur = eval::interpolatePose(gt, r.t, 0.1);
		const auto gtP = gtPrev;
		gtPrev = gtCur;
		if (r.flowObserved.empty() || !gtCur || !gtP) return;
		ego::RgbdFrame f;
		const std::string why = ego::rgbdFrameFrom(scan, cfg.ego.camera, f);
		if (!why.empty()) throw std::runtime_error(why);
		const mrpt::img::TCamera cam = f.camera();
		const CPose3D G = *gtCur - *gtP;  // T_{C(t-1) C(t)}
		const auto c =
		    flow::checkPoseSources(r.flowObserved, f.depth, f.grey, cam,
		                           r.ego.T_CprevC, r.T_CprevC, G, cfg.flow);
		rows.push_back(c.values);
		std::fputs(tableLine(r.index, r.ego.flags, c).c_str(), stdout);
		if (csv) csv->append(csvLine(r.index, r.ego.flags, c));
		if (stripFrames.count(r.index))
			tiles[r.index] = stripTile(scan, f.grey, r.mask, r.index);
	};
	const auto sum = pipeline::runExperiment(cfg, opt);
	if (!sum.error.empty()) throw std::runtime_error(sum.error);
	if (rows.empty())
		throw std::runtime_error(
		    "no frame with flow and ground truth on both sides");
	std::fputs(summary(rows).c_str(), stdout);
	std::printf(
	    "run: mean moving-pixel fraction %.2f %% (%s), %zu of "
	    "%zu frames with the motion not measured\n",
	    100 * sum.meanMovingPixelFraction, sum.variant.c_str(),
	    sum.framesNotMeasured, sum.framesProcessed);
	if (o.strip) writeStrip(*o.strip, tiles);
	return 0;
}

}  // namespace bims::apps
