// Per-frame stages of bims-run outside the grids, on two consecutive frames
// of a rawlog: decoding the observation into grey + depth, the KLT tracker,
// the observed flow (DIS presets x downscale, Farneback), the expected flow
// and the labels. One JSON object per measurement on stdout (json_reporter.h).
//
//   bench_frame --rawlog=RAWLOG [--frame=N] [--cv_threads=K]
//               [benchmark flags]
//
// Default rawlog: the bundled sample (320x240); give a 640x480 bims-sim
// rawlog for VGA figures. --cv_threads calls cv::setNumThreads(K) first
// (default: OpenCV's own choice).
#include <bims/common/rawlog.h>
#include <bims/ego/gyro_klt.h>
#include <bims/ego/rgbd_input.h>
#include <bims/flow/consistency.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/observed_flow.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

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
};
Pair g_pair;

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
		if (k == frame - 1) prev = s;
		if (k == frame)
		{
			g_pair.scan = s;
			break;
		}
		++k;
	}
	if (!prev || !g_pair.scan)
		throw std::runtime_error(path + ": fewer than " +
		                         std::to_string(frame + 1) + " 3D scans");
	const bims::ego::CameraParams noCam;
	for (auto [o, f] : {std::pair{prev.get(), &g_pair.prev},
	                    std::pair{g_pair.scan.get(), &g_pair.cur}})
	{
		const std::string why = bims::ego::rgbdFrameFrom(*o, noCam, *f);
		if (!why.empty()) throw std::runtime_error(path + ": " + why);
		f->grey = f->grey.clone();
	}
	auto& c = g_pair.cam;
	c.ncols = g_pair.cur.grey.cols;
	c.nrows = g_pair.cur.grey.rows;
	const auto& K = g_pair.cur.K;
	c.setIntrinsicParamsFromValues(K(0, 0), K(1, 1), K(0, 2), K(1, 2));
}

void benchDecode(bm::State& st)
{
	const bims::ego::CameraParams noCam;
	bims::ego::RgbdFrame f;
	for (auto _ : st) bims::ego::rgbdFrameFrom(*g_pair.scan, noCam, f);
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

void benchObserved(bm::State& st, bims::flow::FlowParams p)
{
	bims::flow::ObservedFlow of(p);
	for (auto _ : st)
		bm::DoNotOptimize(of.compute(g_pair.prev.grey, g_pair.cur.grey));
}

void benchExpected(bm::State& st)
{
	for (auto _ : st)
		bm::DoNotOptimize(bims::flow::expectedFlowExact(
		    g_pair.cur.depth, g_pair.cam, mrpt::poses::CPose3D()));
}

void benchLabels(bm::State& st)
{
	bims::flow::FlowParams p;
	bims::flow::ObservedFlow of(p);
	const cv::Mat obs = of.compute(g_pair.prev.grey, g_pair.cur.grey);
	const cv::Mat exp =
	    bims::flow::expectedFlowExact(g_pair.cur.depth, g_pair.cam, {});
	for (auto _ : st)
		bm::DoNotOptimize(bims::flow::labelConsistency(
		    obs, exp, g_pair.cur.depth, g_pair.cam, {}, p));
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
	for (const char* preset : {"ultrafast", "fast", "medium"})
		for (int ds : {1, 2})
		{
			bims::flow::FlowParams p;
			p.dis_preset = preset;
			p.downscale = ds;
			reg(std::string("observed/dis_") + preset + "/ds" +
			        std::to_string(ds),
			    [p](bm::State& st) { benchObserved(st, p); });
		}
	reg("expected_exact", benchExpected);
	reg("labels", benchLabels);
}
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		std::string rawlog =
		    std::string(BIMS_SOURCE_DIR) + "/rawlogs/pendulum_slow.rawlog";
		int frame = 20;
		std::vector<char*> rest = {argv[0]};
		for (int i = 1; i < argc; ++i)
		{
			auto val = [&](const char* k)
			{ return bims::bench::flagValue(argv[i], k); };
			if (auto v = val("--rawlog"))
				rawlog = v;
			else if (auto v = val("--frame"))
				frame = std::stoi(v);
			else if (auto v = val("--cv_threads"))
				cv::setNumThreads(std::stoi(v));
			else
				rest.push_back(argv[i]);
		}
		if (frame < 1) throw std::runtime_error("--frame must be >= 1");
		loadPair(rawlog, frame);
		std::cerr << "frames " << frame - 1 << ", " << frame << " of " << rawlog
		          << ": " << g_pair.cur.grey.cols << "x" << g_pair.cur.grey.rows
		          << ", OpenCV threads " << cv::getNumThreads() << "\n";
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
