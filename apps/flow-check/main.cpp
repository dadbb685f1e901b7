// bims-flow-check: where do the flow labels' false positives come from?
//
//   bims-flow-check CONFIG.ini IN.rawlog --gt GT.txt [--frames A:B]
//                   [--csv FRAMES.csv] [--strip OUT.png --strip-frames i,j,..]
//                   [-q]
//
// Runs the pipeline (flow-only variant) and, for every frame, labels the
// observed flow against the expected flow of several relative poses:
//   ego   the egomotion stage's T_CprevC (features; IMU rotation in imu mode)
//   used  the pose the pipeline used (ego, or its dense-flow refinement)
//   gt    the ground truth's relative pose (interpolated at the frame stamps)
//   flow  the SE(3) fitted to the dense observed flow from ego (the pose that
//         best explains the images' static majority; flow_pose.h)
// and prints, per pose, the Diff fraction of the valid-depth pixels and the
// median |observed - expected| flow, plus the rotation / translation of each
// pose against gt and flow. A summary (mean over frames) ends the output.
// --strip writes a picture: for each listed frame the RGB image with the
// used pose's Diff pixels in red (docs/results.md).
#include <bims/common/app.h>
#include <bims/common/output_paths.h>
#include <bims/common/trajectory.h>
#include <bims/ego/rgbd_input.h>
#include <bims/eval/plots.h>
#include <bims/eval/pose_utils.h>
#include <bims/flow/consistency.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/flow_pose.h>
#include <bims/flow/observed_flow.h>
#include <bims/pipeline/run.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>

namespace
{
using mrpt::poses::CPose3D;

double rotDeg(const CPose3D& a, const CPose3D& b)
{
	const auto R = (b - a).getRotationMatrix();  // a^-1 b
	const double c =
	    std::clamp((R(0, 0) + R(1, 1) + R(2, 2) - 1) / 2, -1.0, 1.0);
	return std::acos(c) * 180.0 / M_PI;
}

double transMm(const CPose3D& a, const CPose3D& b)
{
	return 1000.0 * std::sqrt((a.x() - b.x()) * (a.x() - b.x()) +
	                          (a.y() - b.y()) * (a.y() - b.y()) +
	                          (a.z() - b.z()) * (a.z() - b.z()));
}

struct PoseScore
{
	double diffFraction = 0;  // Diff / valid-depth pixels
	double medianPx = 0;      // median |obs - exp| over labelled pixels
};

PoseScore score(const cv::Mat& obs, const cv::Mat& depth,
                const mrpt::img::TCamera& cam, const CPose3D& T,
                const bims::flow::FlowParams& fp, double validPx,
                const cv::Mat& tensor, cv::Mat* labelsOut = nullptr)
{
	const cv::Mat exp = bims::flow::expectedFlow(fp.expected, depth, cam, T);
	bims::flow::LabelStats st;
	const cv::Mat lab =
	    bims::flow::labelConsistency(obs, exp, depth, cam, T, fp, &st, &tensor);
	std::vector<float> d;
	d.reserve(st.diff + st.notDiff);
	for (int v = 0; v < lab.rows; v++)
		for (int u = 0; u < lab.cols; u++)
			if (lab.at<int8_t>(v, u) >= 0)
			{
				const cv::Vec2f e =
				    exp.at<cv::Vec2f>(v, u) - obs.at<cv::Vec2f>(v, u);
				d.push_back(std::hypot(e[0], e[1]));
			}
	PoseScore s;
	s.diffFraction = validPx > 0 ? st.diff / validPx : 0;
	if (!d.empty())
	{
		std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
		s.medianPx = d[d.size() / 2];
	}
	if (labelsOut) *labelsOut = lab;
	return s;
}

}  // namespace

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-flow-check",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "bims: flow-label false positives per relative pose source",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> aCfg(
		        "config", "experiment .ini", true, "", "CONFIG.ini", cmd);
		    TCLAP::UnlabeledValueArg<std::string> aIn(
		        "rawlog", "input rawlog", true, "", "IN.rawlog", cmd);
		    TCLAP::ValueArg<std::string> aGt(
		        "", "gt", "ground-truth TUM trajectory (T_WC)", true, "",
		        "GT.txt", cmd);
		    TCLAP::ValueArg<std::string> aFrames(
		        "", "frames", "3D-scan indices A:B", false, "", "A:B", cmd);
		    TCLAP::ValueArg<std::string> aCsv("", "csv", "per-frame CSV", false,
		                                      "", "FRAMES.csv", cmd);
		    TCLAP::ValueArg<std::string> aStrip(
		        "", "strip", "PNG strip of Diff masks over RGB", false, "",
		        "OUT.png", cmd);
		    TCLAP::ValueArg<std::string> aStripFrames(
		        "", "strip-frames", "comma-separated scan indices for --strip",
		        false, "", "i,j,...", cmd);
		    TCLAP::ValueArg<std::string> aVariant(
		        "", "variant", "pipeline variant (default flow-only)", false,
		        "flow-only", "VARIANT", cmd);
		    TCLAP::SwitchArg aQuiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    bims::checkOutputsSpareInputs(
		        {aCfg.getValue(), aIn.getValue(), aGt.getValue()},
		        bims::givenValues(aCsv, aStrip));

		    bims::pipeline::ExperimentConfig cfg;
		    cfg.loadFromFile(aCfg.getValue());
		    try
		    {
			    cfg.setVariant(bims::parseChoice<bims::pipeline::Variant>(
			        aVariant.getValue()));
		    }
		    catch (const std::invalid_argument& e)
		    {
			    throw bims::UsageError(std::string("--variant: ") + e.what());
		    }
		    const bims::Trajectory gt = bims::loadTumTrajectory(aGt.getValue());
		    const auto stripFrames =
		        bims::parseIndexList(aStripFrames.getValue(), "--strip-frames");
		    if (aStrip.isSet() && stripFrames.empty())
			    throw bims::UsageError("--strip needs --strip-frames");
		    std::map<size_t, cv::Mat> tiles;

		    bims::pipeline::RunOptions opt;
		    opt.rawlogs = {aIn.getValue()};
		    opt.progress = !aQuiet.getValue();
		    opt.frames = bims::pipeline::frameRangeOption(
		        aFrames.getValue(), opt.rawlogs, cfg.ego.sensors.rgbd_label);
		    std::unique_ptr<bims::AppendFile> csv;  // each line checked
		    if (aCsv.isSet())
		    {
			    csv = std::make_unique<bims::AppendFile>(aCsv.getValue());
			    csv->append(
			        "index,flags,valid_px,diff_ego,diff_used,diff_gt,diff_"
			        "flow,px_ego,px_used,px_gt,px_flow,rot_ego_gt_deg,"
			        "rot_ego_flow_deg,rot_gt_flow_deg,rot_used_flow_deg,"
			        "t_ego_gt_mm,t_ego_flow_mm,t_gt_flow_mm,t_used_flow_mm,"
			        "gt_rot_deg,gt_t_mm,edge_share_used\n");
		    }
		    std::printf(
		        "# index flags | Diff%% ego used gt flow | median px ego used "
		        "gt flow | rot deg ego-gt ego-flow gt-flow used-flow | t mm "
		        "ego-gt ego-flow gt-flow used-flow | gt motion deg mm | Diff "
		        "share on depth edges (used)\n");
		    std::optional<CPose3D> gtPrev;
		    std::vector<std::vector<double>> cols;
		    auto fp = cfg.flow;
		    bims::flow::FlowParams fpSE3 = fp;
		    fpSE3.refine_pose = bims::flow::RefinePose::SE3;
		    const auto refineP = bims::flow::flowPoseParamsFrom(fpSE3);
		    opt.onFrame = [&](const bims::pipeline::FrameResult& r,
		                      const mrpt::obs::CObservation3DRangeScan& scan)
		    {
			    const auto gtCur = bims::eval::interpolatePose(gt, r.t, 0.1);
			    const auto gtP = gtPrev;
			    gtPrev = gtCur;
			    if (r.flowObserved.empty() || !gtCur || !gtP) return;
			    bims::ego::RgbdFrame f;
			    const std::string why =
			        bims::ego::rgbdFrameFrom(scan, cfg.ego.camera, f);
			    if (!why.empty()) throw std::runtime_error(why);
			    mrpt::img::TCamera cam;
			    cam.ncols = static_cast<uint32_t>(f.depth.cols);
			    cam.nrows = static_cast<uint32_t>(f.depth.rows);
			    cam.setIntrinsicParamsFromValues(f.K(0, 0), f.K(1, 1),
			                                     f.K(0, 2), f.K(1, 2));
			    const double validPx = cv::countNonZero(f.depth > 0);
			    const CPose3D G = *gtCur - *gtP;  // T_{C(t-1) C(t)}
			    const CPose3D E = r.ego.T_CprevC, U = r.T_CprevC;
			    const cv::Mat S =
			        bims::flow::structureTensor(f.grey, fp.texture_window_px);
			    const auto ref = bims::flow::refinePoseWithFlow(
			        r.flowObserved, f.depth, cam, E, refineP, nullptr, &S);
			    const CPose3D V = ref.T_CprevC;
			    cv::Mat labU;
			    const auto sE =
			        score(r.flowObserved, f.depth, cam, E, fp, validPx, S);
			    const auto sU = score(r.flowObserved, f.depth, cam, U, fp,
			                          validPx, S, &labU);
			    const auto sG =
			        score(r.flowObserved, f.depth, cam, G, fp, validPx, S);
			    const auto sV =
			        score(r.flowObserved, f.depth, cam, V, fp, validPx, S);
			    const cv::Mat edges =
			        bims::flow::depthEdgeMask(f.depth, 0.05, 2);
			    const double nDiff = cv::countNonZero(labU == 1);
			    const double nDiffEdge =
			        cv::countNonZero((labU == 1) & (edges > 0));
			    const double edgeShare = nDiff > 0 ? nDiffEdge / nDiff : 0;
			    const std::vector<double> row = {sE.diffFraction * 100,
			                                     sU.diffFraction * 100,
			                                     sG.diffFraction * 100,
			                                     sV.diffFraction * 100,
			                                     sE.medianPx,
			                                     sU.medianPx,
			                                     sG.medianPx,
			                                     sV.medianPx,
			                                     rotDeg(E, G),
			                                     rotDeg(E, V),
			                                     rotDeg(G, V),
			                                     rotDeg(U, V),
			                                     transMm(E, G),
			                                     transMm(E, V),
			                                     transMm(G, V),
			                                     transMm(U, V),
			                                     rotDeg(CPose3D(), G),
			                                     transMm(CPose3D(), G),
			                                     edgeShare};
			    if (cols.empty()) cols.resize(row.size());
			    for (size_t k = 0; k < row.size(); k++)
				    cols[k].push_back(row[k]);
			    std::printf(
			        "%4zu %4u | %5.1f %5.1f %5.1f %5.1f | %5.2f %5.2f %5.2f "
			        "%5.2f "
			        "| %5.2f %5.2f %5.2f %5.2f | %5.1f %5.1f %5.1f %5.1f | "
			        "%5.2f "
			        "%5.1f | %4.2f\n",
			        r.index, r.ego.flags, row[0], row[1], row[2], row[3],
			        row[4], row[5], row[6], row[7], row[8], row[9], row[10],
			        row[11], row[12], row[13], row[14], row[15], row[16],
			        row[17], row[18]);
			    if (csv)
			    {
				    std::ostringstream line;
				    line << r.index << "," << r.ego.flags << "," << validPx;
				    for (double x : row) line << "," << x;
				    line << "\n";
				    csv->append(line.str());
			    }
			    if (stripFrames.count(r.index))
			    {
				    cv::Mat rgb;
				    cv::cvtColor(f.grey, rgb, cv::COLOR_GRAY2BGR);
				    if (scan.hasIntensityImage)
				    {
					    const cv::Mat c = scan.intensityImage.asCvMatRef();
					    if (c.channels() == 3 && c.size() == rgb.size())
						    rgb = c.clone();
				    }
				    cv::Mat red(rgb.size(), CV_8UC3, cv::Scalar(0, 0, 255));
				    cv::Mat blend;
				    cv::addWeighted(rgb, 0.45, red, 0.55, 0, blend);
				    blend.copyTo(rgb, r.mask > 0);
				    cv::putText(rgb, "frame " + std::to_string(r.index),
				                {10, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.9,
				                cv::Scalar(255, 255, 255), 2);
				    tiles[r.index] = rgb;
			    }
		    };
		    const auto sum = bims::pipeline::runExperiment(cfg, opt);
		    if (!sum.error.empty()) throw std::runtime_error(sum.error);
		    if (cols.empty())
			    throw std::runtime_error(
			        "no frame with flow and ground truth on both sides");
		    std::printf("# mean over %zu frames:\n", cols[0].size());
		    const char* names[] = {
		        "diff_%_ego",       "diff_%_used",     "diff_%_gt",
		        "diff_%_flow",      "median_px_ego",   "median_px_used",
		        "median_px_gt",     "median_px_flow",  "rot_ego_gt_deg",
		        "rot_ego_flow_deg", "rot_gt_flow_deg", "rot_used_flow_deg",
		        "t_ego_gt_mm",      "t_ego_flow_mm",   "t_gt_flow_mm",
		        "t_used_flow_mm",   "gt_rot_deg",      "gt_t_mm",
		        "edge_share_used"};
		    for (size_t k = 0; k < cols.size(); k++)
		    {
			    auto v = cols[k];
			    double m = 0;
			    for (double x : v) m += x;
			    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
			    std::printf("%-18s mean %8.3f median %8.3f\n", names[k],
			                m / v.size(), v[v.size() / 2]);
		    }
		    std::printf(
		        "run: mean moving-pixel fraction %.2f %% (%s), %zu of "
		        "%zu frames flagged by egomotion\n",
		        100 * sum.meanMovingPixelFraction, sum.variant.c_str(),
		        sum.framesFlagged, sum.framesProcessed);
		    if (aStrip.isSet())
		    {
			    if (tiles.empty())
				    throw std::runtime_error("--strip: none of the frames ran");
			    std::vector<cv::Mat> row;
			    for (auto& [i, m] : tiles) row.push_back(m);
			    bims::eval::writePng(aStrip.getValue(),
			                         bims::eval::imageStrip(row, 0.5));
			    std::printf("strip: %s (%zu frames)\n",
			                aStrip.getValue().c_str(), tiles.size());
		    }
		    return 0;
	    });
}
