#include <bims/apps/app.h>
#include <bims/common/rawlog.h>
#include <bims/common/trajectory.h>
#include <bims/eval/depth_consistency.h>
#include <bims/eval/pose_utils.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <algorithm>
#include <cstdio>
#include <deque>
#include <stdexcept>

#include "commands.h"

namespace ev = bims::eval;

int cmdDepthConsistency(int argc, char** argv)
{
	TCLAP::CmdLine cmd(
	    "Checks poses with depth: the depth of scan k, back-projected with "
	    "T_WC(k) and re-projected into scan k+gap with T_WC(k+gap), is "
	    "compared "
	    "with that scan's depth. Prints the median |dz| over all pairs, and "
	    "the same assuming no motion as a baseline.",
	    ' ', bims::version());
	TCLAP::UnlabeledValueArg<std::string> rawlog(
	    "RAWLOG", "rawlog with 3D scans", true, "", "IN.rawlog", cmd);
	TCLAP::UnlabeledValueArg<std::string> gtArg(
	    "GT", "poses T_WC (TUM format), interpolated at the scans' stamps",
	    true, "", "GT.txt", cmd);
	TCLAP::ValueArg<int> gap("", "gap", "frames between compared scans (15)",
	                         false, 15, "N", cmd);
	TCLAP::ValueArg<int> step("", "step", "pixel subsampling (4)", false, 4,
	                          "S", cmd);
	TCLAP::ValueArg<int> maxFrames("", "max-frames",
	                               "use only the first N scans (0 = all)",
	                               false, 0, "N", cmd);
	bims::parseCommandLine(cmd, argc, argv);
	bims::inRange(maxFrames, 0, 100000000, "0 = all");
	if (gap.getValue() < 1) throw std::runtime_error("--gap must be >= 1");

	const auto gt = bims::loadTumTrajectory(gtArg.getValue());
	if (gt.empty())
		throw std::runtime_error(gtArg.getValue() + ": trajectory is empty");
	bims::RawlogReader r(rawlog.getValue());
	struct Frame
	{
		cv::Mat depth;
		mrpt::poses::CPose3D T_WC;
	};
	std::deque<std::optional<Frame>> window;
	std::vector<double> med, within, medStill;
	ev::CameraIntrinsics cam;
	int n = 0;
	while (auto o = r.next())
	{
		auto s =
		    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(o);
		if (!s) continue;
		if (maxFrames.getValue() > 0 && n >= maxFrames.getValue()) break;
		n++;
		s->load();
		cam = ev::intrinsicsFromObservation(*s);
		const auto T =
		    ev::interpolatePose(gt, mrpt::Clock::toDouble(s->timestamp), 0.1);
		std::optional<Frame> f;
		if (T) f = Frame{ev::depthFromObservation(*s), *T};
		window.push_back(f);
		if (window.size() > static_cast<size_t>(gap.getValue()))
		{
			const auto& a = window.front();
			const auto& b = window.back();
			if (a && b)
			{
				const auto ag = ev::depthAgreement(
				    a->depth, a->T_WC, b->depth, b->T_WC, cam, step.getValue());
				const auto st = ev::depthAgreement(a->depth, {}, b->depth, {},
				                                   cam, step.getValue());
				if (ag.compared > 0)
				{
					med.push_back(ag.medianAbs);
					within.push_back(ag.fractionWithin5cm);
					medStill.push_back(st.medianAbs);
				}
			}
			window.pop_front();
		}
	}
	if (med.empty())
		throw std::runtime_error(
		    rawlog.getValue() + " with " + gtArg.getValue() +
		    ": no pair of scans with poses (no time overlap?)");
	auto median = [](std::vector<double> v)
	{
		std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
		return v[v.size() / 2];
	};
	std::printf(
	    "depth-consistency pairs %zu gap %d median_abs_dz %.4f m within_5cm "
	    "%.3f no_motion_median_abs_dz %.4f m\n",
	    med.size(), gap.getValue(), median(med), median(within),
	    median(medStill));
	return 0;
}
