// bims-eval depth-consistency (eval_run.h).
#include <bims/apps/eval_run.h>
#include <bims/eval/depth_consistency.h>
#include <bims/eval/pose_utils.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <algorithm>
#include <cstdio>
#include <deque>
#include <optional>
#include <stdexcept>

namespace bims::apps
{
namespace ev = bims::eval;

int runDepthConsistency(const DepthConsistencyOptions& o)
{
	if (o.gap < 1) throw std::runtime_error("--gap must be >= 1");

	const auto gt = loadTumTrajectory(o.gt);
	if (gt.empty()) throw std::runtime_error(o.gt + ": trajectory is empty");
	RawlogReader r(o.rawlog);
	struct Frame
	{
		cv::Mat depth;
		mrpt::poses::CPose3D T_WC;
	};
	std::deque<std::optional<Frame>> window;
	std::vector<double> med, within, medStill;
	ev::CameraIntrinsics cam;
	int n = 0;
	while (auto obs = r.next())
	{
		auto s =
		    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(obs);
		if (!s) continue;
		if (o.maxFrames > 0 && n >= o.maxFrames) break;
		n++;
		s->load();
		cam = ev::intrinsicsFromObservation(*s);
		const auto T =
		    ev::interpolatePose(gt, mrpt::Clock::toDouble(s->timestamp), 0.1);
		std::optional<Frame> f;
		if (T) f = Frame{ev::depthFromObservation(*s), *T};
		window.push_back(f);
		if (window.size() > static_cast<size_t>(o.gap))
		{
			const auto& a = window.front();
			const auto& b = window.back();
			if (a && b)
			{
				const auto ag = ev::depthAgreement(a->depth, a->T_WC, b->depth,
				                                   b->T_WC, cam, o.step);
				const auto st =
				    ev::depthAgreement(a->depth, {}, b->depth, {}, cam, o.step);
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
		    o.rawlog + " with " + o.gt +
		    ": no pair of scans with poses (no time overlap?)");
	auto median = [](std::vector<double> v)
	{
		std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
		return v[v.size() / 2];
	};
	std::printf(
	    "depth-consistency pairs %zu gap %d median_abs_dz %.4f m within_5cm "
	    "%.3f no_motion_median_abs_dz %.4f m\n",
	    med.size(), o.gap, median(med), median(within), median(medStill));
	return 0;
}

}  // namespace bims::apps
