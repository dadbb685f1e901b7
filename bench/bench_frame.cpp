// Per-frame stages of bims-run outside the grids, on two consecutive frames
// of a rawlog: decoding the observation into grey + depth, the KLT tracker,
// the observed flow (DIS presets x downscale, Farneback), and the flow
// stages as the pipeline runs them with an experiment's [flow] section:
// the derotated observed flow and its parts (warp, structure tensor, DIS,
// composition), the expected flow and the labels; the surface fill of a
// mask. One JSON object per
// measurement on stdout (json_reporter.h); "proc_cpu_ms" is the CPU time of
// the whole process per iteration (OpenCV's worker threads included).
//
//   bench_frame --rawlog=RAWLOG [--frame=N] [--cv_threads=K]
//               [--config=EXP.ini] [--gt=GT.txt] [benchmark flags]
//
// Default rawlog: the bundled sample (320x240); give a 640x480 bims-sim
// rawlog for VGA figures. --cv_threads calls cv::setNumThreads(K) first
// (default: OpenCV's own choice). --config: the [flow] section to use
// (default config/default.ini). --gt: the relative pose of the pair from a
// TUM trajectory with one pose per 3D scan (bims-sim's NAME_gt/
// groundtruth.txt); without it a made-up pose of a few degrees and
// centimetres (the labels are then mostly Diff). The map-anchored tracking's
// dense alignment (ego/dense_*) uses the experiment's [anchor] section, the
// earlier frame as the keyframe, and two initial guesses (no motion, and the
// pair's pose), as KeyframeAnchor::track gives it.
#include <bims/ego/dense_align.h>
#include <bims/ego/gyro_klt.h>
#include <bims/ego/rgbd_input.h>
#include <bims/flow/consistency.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/observed_flow.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/pipeline/surface_fill.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <cmath>
#include <ctime>
#include <fstream>
#include <iostream>
#include <stdexcept>

#include "json_reporter.h"

namespace bm = benchmark;

namespace
{
struct Pair
{
	mrpt::obs::CObservation3DRangeScan::Ptr scan;
	bims::ego::RgbdFrame prev, cur;
	mrpt::img::TCamera cam;
	double tPrev = 0, tCur = 0;  ///< timestamps [s]
};
Pair g_pair;
// The experiment's [flow] section, and the relative pose of the flow stages
// (the derotation's homography is its rotation, the expected flow uses all
// of it): the ground truth's with --gt, otherwise a pan of a few degrees and
// a step of a few centimetres.
bims::flow::FlowParams g_flow;
bims::ego::AnchorParams g_anchor;  ///< the experiment's [anchor]
mrpt::poses::CPose3D g_T_CprevC(0.02, -0.01, 0.03, 0.035, -0.02, 0.01);

/** T_{C(t-1) C(t)} of the pair from a TUM trajectory with one line per 3D
 * scan (bims-sim's groundtruth.txt). */
mrpt::poses::CPose3D relativePoseFromGt(const std::string& path, int frame)
{
	const bims::Trajectory gt = bims::loadTumTrajectory(path);
	if (static_cast<int>(gt.size()) <= frame)
		throw std::runtime_error(path + ": fewer than " +
		                         std::to_string(frame + 1) + " poses");
	const auto& a = gt[frame - 1];
	const auto& b = gt[frame];
	if (std::abs(a.t - g_pair.tPrev) > 1e-3 ||
	    std::abs(b.t - g_pair.tCur) > 1e-3)
		throw std::runtime_error(path +
		                         ": timestamps differ from the rawlog's scans");
	return b.T_WC - a.T_WC;
}

double processCpuMs()
{
	timespec ts{};
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/** Sets the counter proc_cpu_ms of \a st to the process CPU time per
 * iteration over the object's lifetime (every thread). */
class ProcCpu
{
 public:
	explicit ProcCpu(bm::State& st) : st_(st), t0_(processCpuMs()) {}
	~ProcCpu()
	{
		st_.counters["proc_cpu_ms"] =
		    bm::Counter(processCpuMs() - t0_, bm::Counter::kAvgIterations);
	}

 private:
	bm::State& st_;
	double t0_;
};

void loadPair(const std::string& path, int frame)
{
	bims::RawlogReader r(path);
	int k = 0;
	mrpt::obs::CObservation3DRangeScan::Ptr prev;
	while (auto o = r.next())
	{
		auto s =
		    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(o);
		if (!s) continue;
		if (k == frame - 1)
		{
			prev = s;
			g_pair.tPrev = mrpt::Clock::toDouble(s->timestamp);
		}
		if (k == frame)
		{
			g_pair.scan = s;
			g_pair.tCur = mrpt::Clock::toDouble(s->timestamp);
			break;
		}
		++k;
	}
	if (!prev || !g_pair.scan)
		throw std::runtime_error(path + ": fewer than " +
		                         std::to_string(frame + 1) + " 3D scans");
	const bims::sensors::CameraParams noCam;
	for (auto [o, f] : {std::pair{prev.get(), &g_pair.prev},
	                    std::pair{g_pair.scan.get(), &g_pair.cur}})
	{
		const std::string why = bims::ego::rgbdFrameFrom(*o, noCam, *f);
		if (!why.empty()) throw std::runtime_error(path + ": " + why);
		f->grey = f->grey.clone();
	}
	g_pair.cam = g_pair.cur.camera();
}

void benchDecode(bm::State& st)
{
	const bims::sensors::CameraParams noCam;
	bims::ego::RgbdFrame f;
	for (auto _ : st)
	{
		const std::string err =
		    bims::ego::rgbdFrameFrom(*g_pair.scan, noCam, f);
		if (!err.empty())
		{
			st.SkipWithError(err.c_str());
			break;
		}
	}
}

void benchTracker(bm::State& st)
{
	bims::ego::GyroAidedKLT klt;
	const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
	for (auto _ : st)
	{
		st.PauseTiming();
		klt.reset();
		klt.track(g_pair.prev.grey, g_pair.prev.K, nullptr, nullptr);
		st.ResumeTiming();
		bm::DoNotOptimize(
		    klt.track(g_pair.cur.grey, g_pair.cur.K, &I, nullptr));
	}
	st.counters["tracks"] = klt.stats().tracked;
}

// The tracker's parts, as GyroAidedKLT runs them with its defaults.
void benchPyramid(bm::State& st)
{
	std::vector<cv::Mat> pyr;
	for (auto _ : st)
		cv::buildOpticalFlowPyramid(g_pair.cur.grey, pyr, cv::Size(15, 15), 2,
		                            true);
}

void benchFast(bm::State& st)
{
	std::vector<cv::KeyPoint> kps;
	for (auto _ : st) cv::FAST(g_pair.cur.grey, kps, 15, true);
	st.counters["keypoints"] = static_cast<double>(kps.size());
}

void benchMaskDilate(bm::State& st)
{
	cv::Mat mask(g_pair.cur.grey.size(), CV_8UC1, cv::Scalar(0)), out;
	cv::circle(mask, {mask.cols / 2, mask.rows / 2}, mask.rows / 6, 255, -1);
	const cv::Mat k =
	    cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(17, 17));
	for (auto _ : st) cv::dilate(mask, out, k);
}

// The surface fill of a mask whose disc covers a third of the image's
// height (bims/pipeline/surface_fill.h): labelling the depth's surfaces,
// the distance to the moving pixels and the fill. Any surface up to the
// whole image may be filled here, so every step runs.
void benchSurfaceFill(bm::State& st)
{
	const cv::Mat& depth = g_pair.cur.depth;
	cv::Mat mask(depth.size(), CV_8UC1, cv::Scalar(0)), m;
	cv::circle(mask, {mask.cols / 2, mask.rows / 2}, mask.rows / 6, 255, -1);
	bims::pipeline::SurfaceFillParams p;
	p.maxArea = 1.0;
	p.minMoving = 0.01;
	bims::pipeline::SurfaceFillStats fs;
	for (auto _ : st)
	{
		mask.copyTo(m);
		fs = bims::pipeline::fillMovingSurfaces(depth, g_pair.cur.K, m, p);
	}
	st.counters["filled"] = fs.filled;
	st.counters["added"] = fs.added;
}

void benchObserved(bm::State& st, bims::flow::FlowParams p)
{
	bims::flow::ObservedFlow of(p);
	ProcCpu cpu(st);
	for (auto _ : st)
		bm::DoNotOptimize(of.compute(g_pair.prev.grey, g_pair.cur.grey));
}

cv::Matx33d derotation()
{
	return bims::flow::rotationHomography(g_pair.cam, g_T_CprevC);
}

cv::Mat warpedPrev()
{
	cv::Mat w;
	cv::warpPerspective(
	    g_pair.prev.grey, w, derotation(), g_pair.prev.grey.size(),
	    cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
	return w;
}

// The pipeline's observed flow: ObservedFlow::computeDerotated with the
// experiment's [flow] (warp, structure tensor, DIS, composition).
void benchDerotated(bm::State& st)
{
	bims::flow::ObservedFlow of(g_flow);
	const cv::Matx33d H = derotation();
	ProcCpu cpu(st);
	for (auto _ : st)
		bm::DoNotOptimize(
		    of.computeDerotated(g_pair.prev.grey, g_pair.cur.grey, H));
}

// Its parts.
void benchWarp(bm::State& st)
{
	const cv::Matx33d H = derotation();
	cv::Mat w;
	ProcCpu cpu(st);
	for (auto _ : st)
		cv::warpPerspective(g_pair.prev.grey, w, H, g_pair.prev.grey.size(),
		                    cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
		                    cv::BORDER_REPLICATE);
}

// As ObservedFlow computes it: its buffers reused.
void benchTensor(bm::State& st)
{
	bims::flow::TensorBuffers buf;
	cv::Mat out;
	ProcCpu cpu(st);
	for (auto _ : st)
		bims::flow::structureTensor(g_pair.cur.grey, g_flow.texture_window_px,
		                            out, buf);
}

void benchDisWarped(bm::State& st)
{
	bims::flow::FlowParams p = g_flow;  // DIS alone: no tensor
	p.visible_change_grey = 0;
	p.refine_pose = bims::flow::RefinePose::None;
	bims::flow::ObservedFlow of(p);
	const cv::Mat w = warpedPrev();
	ProcCpu cpu(st);
	for (auto _ : st) bm::DoNotOptimize(of.compute(w, g_pair.cur.grey));
}

void benchCompose(bm::State& st)
{
	bims::flow::FlowParams p = g_flow;
	p.visible_change_grey = 0;
	p.refine_pose = bims::flow::RefinePose::None;
	bims::flow::ObservedFlow of(p);
	const cv::Mat residual = of.compute(warpedPrev(), g_pair.cur.grey);
	const cv::Matx33d H = derotation();
	cv::Mat flow;
	ProcCpu cpu(st);
	for (auto _ : st) bims::flow::composeWithHomography(residual, H, flow);
}

void benchExpected(bm::State& st)
{
	ProcCpu cpu(st);
	for (auto _ : st)
		bm::DoNotOptimize(bims::flow::expectedFlowExact(
		    g_pair.cur.depth, g_pair.cam, g_T_CprevC));
}

// The labels as the pipeline makes them: the derotated observed flow, the
// exact expected flow and (visibility gate) the structure tensor.
void benchLabels(bm::State& st)
{
	bims::flow::ObservedFlow of(g_flow);
	const cv::Mat obs =
	    of.computeDerotated(g_pair.prev.grey, g_pair.cur.grey, derotation());
	const cv::Mat exp =
	    bims::flow::expectedFlowExact(g_pair.cur.depth, g_pair.cam, g_T_CprevC);
	const cv::Mat* tensor = of.tensor().empty() ? nullptr : &of.tensor();
	bims::flow::LabelStats stats;
	ProcCpu cpu(st);
	for (auto _ : st)
		bm::DoNotOptimize(
		    bims::flow::labelConsistency(obs, exp, g_pair.cur.depth, g_pair.cam,
		                                 g_T_CprevC, g_flow, &stats, tensor));
	st.counters["diff"] = static_cast<double>(stats.diff);
	st.counters["notdiff"] = static_cast<double>(stats.notDiff);
}

// The keyframe's pyramid with its normals and gradients, and the frame's.
void benchDenseBuild(bm::State& st)
{
	bims::ego::DenseFrame ref, cur;
	ProcCpu cpu(st);
	for (auto _ : st)
	{
		ref.build(g_pair.prev.grey, g_pair.prev.depth, g_pair.prev.K, g_anchor);
		ref.prepareReference(g_anchor);
		cur.build(g_pair.cur.grey, g_pair.cur.depth, g_pair.cur.K, g_anchor);
	}
}

// The alignment of the frame to the keyframe (Levenberg-Marquardt over the
// levels, both guesses, the IMU's rotation as prior; the final outlier
// image).
void benchDenseAlign(bm::State& st)
{
	bims::ego::DenseFrame ref, cur;
	ref.build(g_pair.prev.grey, g_pair.prev.depth, g_pair.prev.K, g_anchor);
	ref.prepareReference(g_anchor);
	cur.build(g_pair.cur.grey, g_pair.cur.depth, g_pair.cur.K, g_anchor);
	const Eigen::Matrix3d R = g_T_CprevC.getRotationMatrix().asEigen();
	const Eigen::Vector3d t(g_T_CprevC.x(), g_T_CprevC.y(), g_T_CprevC.z());
	const std::vector<bims::ego::InitialGuess> inits = {
	    {Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()}, {R, t}};
	bims::ego::DenseAlignResult r;
	ProcCpu cpu(st);
	for (auto _ : st)
		r = bims::ego::alignDense(
		    ref, cur, inits, g_anchor, &R,
		    g_anchor.rotation_prior_sigma_deg * M_PI / 180);
	st.counters["iterations"] = r.iterations;
	st.counters["inliers"] = r.inliers;
	st.counters["ok"] = r.ok;
}

template <class F>
void reg(const std::string& name, F f)
{
	bm::RegisterBenchmark(name.c_str(), f)
	    ->Unit(bm::kMillisecond)
	    ->UseRealTime()
	    ->Repetitions(5)
	    ->ReportAggregatesOnly();
}

void registerAll()
{
	reg("decode", benchDecode);
	reg("tracker", benchTracker);
	reg("tracker/pyramid", benchPyramid);
	reg("tracker/fast", benchFast);
	reg("tracker/mask_dilate", benchMaskDilate);
	reg("surface_fill", benchSurfaceFill);
	for (const char* preset : {"ultrafast", "fast", "medium"})
		for (int ds : {1, 2})
		{
			bims::flow::FlowParams p;  // DIS alone: no tensor
			p.visible_change_grey = 0;
			p.dis_preset = bims::parseChoice<bims::flow::DisPreset>(preset);
			p.downscale = ds;
			reg(std::string("observed/dis_") + preset + "/ds" +
			        std::to_string(ds),
			    [p](bm::State& st) { benchObserved(st, p); });
		}
	reg("observed/derotated", benchDerotated);
	reg("observed/warp", benchWarp);
	reg("observed/tensor", benchTensor);
	reg("observed/dis", benchDisWarped);
	reg("observed/compose", benchCompose);
	reg("expected_exact", benchExpected);
	reg("labels", benchLabels);
	reg("ego/dense_build", benchDenseBuild);
	reg("ego/dense_align", benchDenseAlign);
}
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		std::string rawlog =
		    std::string(BIMS_SOURCE_DIR) + "/rawlogs/pendulum_slow.rawlog";
		int frame = 20;
		std::string gt;
		std::string config =
		    std::string(BIMS_SOURCE_DIR) + "/config/default.ini";
		std::vector<char*> rest = {argv[0]};
		for (int i = 1; i < argc; ++i)
		{
			auto val = [&](const char* k)
			{ return bims::bench::flagValue(argv[i], k); };
			if (auto v = val("--rawlog"))
				rawlog = v;
			else if (auto v = val("--frame"))
				frame = std::stoi(v);
			else if (auto v = val("--gt"))
				gt = v;
			else if (auto v = val("--config"))
				config = v;
			else if (auto v = val("--cv_threads"))
				cv::setNumThreads(std::stoi(v));
			else
				rest.push_back(argv[i]);
		}
		if (frame < 1) throw std::runtime_error("--frame must be >= 1");
		loadPair(rawlog, frame);
		if (!gt.empty()) g_T_CprevC = relativePoseFromGt(gt, frame);
		if (!std::ifstream(config))
			throw std::runtime_error("cannot open " + config);
		const mrpt::config::CConfigFile cfg(config);
		g_flow.loadFromConfigFile(cfg, "flow");
		g_anchor.loadFromConfigFile(cfg, "anchor");
		std::cerr << "frames " << frame - 1 << ", " << frame << " of " << rawlog
		          << ": " << g_pair.cur.grey.cols << "x" << g_pair.cur.grey.rows
		          << ", OpenCV threads " << cv::getNumThreads()
		          << ", [flow] and [anchor] of " << config << ", T_CprevC "
		          << g_T_CprevC << "\n";
		registerAll();
		int n = int(rest.size());
		return bims::bench::runWithJsonLines(n, rest.data());
	}
	catch (const std::exception& e)
	{
		std::cerr << "bench_frame: error: " << e.what() << "\n";
		return 1;
	}
}
