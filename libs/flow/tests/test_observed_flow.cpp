#include <bims/common/config.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/observed_flow.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <algorithm>
#include <vector>

#include "test_util.h"

using namespace bims::flow;

namespace
{
/** Median end-point error against a constant flow, over the inner image. */
double medianError(const cv::Mat& flow, double fx, double fy)
{
	std::vector<double> e;
	for (int v = 20; v < flow.rows - 20; v += 2)
		for (int u = 20; u < flow.cols - 20; u += 2)
		{
			const auto f = flow.at<cv::Vec2f>(v, u);
			e.push_back(std::hypot(f[0] - fx, f[1] - fy));
		}
	std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
	return e[e.size() / 2];
}
}  // namespace

TEST(ObservedFlow, RecoversASubpixelShiftWithEveryMethod)
{
	const cv::Mat prev = test::texture(320, 240, 7);
	const cv::Mat cur = test::shifted(prev, 2.3, -1.7);  // content moved by +d
	struct Case
	{
		std::string method;
		int downscale;
		double tol;
	};
	for (const auto& c : {Case{"dis", 1, 0.15}, Case{"farneback", 1, 0.15},
	                      Case{"dis", 2, 0.35}})
	{
		FlowParams p;
		p.method = bims::parseChoice<FlowMethod>(c.method);
		p.downscale = c.downscale;
		ObservedFlow of(p);
		const cv::Mat flow = of.compute(prev, cur);
		ASSERT_EQ(flow.type(), CV_32FC2);
		ASSERT_EQ(flow.size(), cur.size());
		// backward flow: u_prev - u_cur = -d
		EXPECT_LT(medianError(flow, -2.3, 1.7), c.tol)
		    << c.method << " /" << c.downscale;
	}
}

TEST(ObservedFlow, RejectsMismatchedImages)
{
	ObservedFlow of;
	EXPECT_THROW(of.compute(cv::Mat(10, 10, CV_8UC1), cv::Mat(10, 12, CV_8UC1)),
	             std::invalid_argument);
	EXPECT_THROW(of.compute(cv::Mat(), cv::Mat()), std::invalid_argument);
	EXPECT_THROW(of.compute(cv::Mat(10, 10, CV_8UC3), cv::Mat(10, 10, CV_8UC3)),
	             std::invalid_argument);
}

// Issue 55: OpenCV's DIS reads outside an image whose size does not reach
// its preset's finest scale (SIGSEGV at 40 x 8, 128 x 24, 320 x 20 ...);
// the observed flow names the least size instead, and runs on every size
// it accepts.
TEST(ObservedFlow, ImagesTooSmallForDisAreRefusedNotRun)
{
	FlowParams fast;
	EXPECT_EQ(
	    observedFlowSizeProblem(fast, 40, 8),
	    "40x8 is too small for the observed flow (OpenCV's DIS, preset "
	    "fast): it needs at least 32 pixels on the shorter side and 91 on "
	    "the longer one ([flow] method = farneback takes any size)");
	// the least sizes, each preset (downscale: of the images DIS sees)
	struct Least
	{
		const char* preset;
		int downscale, shorter, longer;
	};
	for (const Least& l :
	     {Least{"fast", 1, 32, 91}, Least{"ultrafast", 1, 32, 91},
	      Least{"medium", 1, 16, 46}, Least{"fast", 2, 64, 182}})
	{
		FlowParams p;
		p.dis_preset = bims::parseChoice<DisPreset>(l.preset);
		p.downscale = l.downscale;
		const std::string what =
		    std::string(l.preset) + " /" + std::to_string(l.downscale);
		EXPECT_EQ(observedFlowSizeProblem(p, l.longer, l.shorter), "") << what;
		EXPECT_EQ(observedFlowSizeProblem(p, l.shorter, l.longer), "") << what;
		EXPECT_NE(observedFlowSizeProblem(p, l.longer - l.downscale, l.shorter),
		          "")
		    << what;
		EXPECT_NE(observedFlowSizeProblem(p, l.longer, l.shorter - l.downscale),
		          "")
		    << what;
	}
	// every size: refused, or run (sizes where DIS crashed among them)
	for (const char* preset : {"fast", "ultrafast", "medium"})
		for (int w : {1, 4, 12, 24, 32, 40, 64, 91, 128, 320, 700})
			for (int h : {1, 8, 16, 20, 24, 32, 91})
			{
				FlowParams p;
				p.dis_preset = bims::parseChoice<DisPreset>(preset);
				ObservedFlow of(p);
				const cv::Mat prev = test::texture(w, h, 5);
				const cv::Mat cur = test::shifted(prev, 0.7, 0.2);
				if (observedFlowSizeProblem(p, w, h).empty())
					EXPECT_EQ(of.compute(prev, cur).size(), cur.size())
					    << preset << " " << w << "x" << h;
				else
					EXPECT_THROW(of.compute(prev, cur), std::invalid_argument)
					    << preset << " " << w << "x" << h;
			}
	// Farneback takes any size but an empty one
	FlowParams fb;
	fb.method = FlowMethod::Farneback;
	EXPECT_EQ(observedFlowSizeProblem(fb, 1, 1), "");
	fb.downscale = 2;
	EXPECT_NE(observedFlowSizeProblem(fb, 1, 1), "");
}

namespace
{
/** Median end-point error against a reference flow over the pixels whose
 * reference stays at least \a margin px inside the image. */
double medianErrorAgainst(const cv::Mat& flow, const cv::Mat& ref, int margin)
{
	std::vector<double> e;
	for (int v = margin; v < flow.rows - margin; v += 2)
		for (int u = margin; u < flow.cols - margin; u += 2)
		{
			const auto r = ref.at<cv::Vec2f>(v, u);
			const double x = u + r[0], y = v + r[1];
			if (!(x >= margin && y >= margin && x < flow.cols - margin &&
			      y < flow.rows - margin))
				continue;
			const auto f = flow.at<cv::Vec2f>(v, u);
			e.push_back(std::hypot(f[0] - r[0], f[1] - r[1]));
		}
	if (e.empty()) return 1e9;
	std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
	return e[e.size() / 2];
}
}  // namespace

TEST(ObservedFlow, RotationHomographyMapsPixelsAsTheHomographyFlow)
{
	const auto cam = test::vgaCamera(320, 240);
	const mrpt::poses::CPose3D R(0.3, -0.2, 0.1, 0.12, -0.05, 0.03);
	const cv::Matx33d H = rotationHomography(cam, R);  // translation ignored
	const cv::Mat h = homographyFlow(cam, R);
	for (int v = 0; v < 240; v += 17)
		for (int u = 0; u < 320; u += 13)
		{
			const cv::Vec3d p = H * cv::Vec3d(u, v, 1);
			const auto f = h.at<cv::Vec2f>(v, u);
			EXPECT_NEAR(p[0] / p[2] - u, f[0], 1e-3);
			EXPECT_NEAR(p[1] / p[2] - v, f[1], 1e-3);
		}
}

TEST(ObservedFlow, DerotationRecoversAFastRotationThatPlainDisMisses)
{
	// A camera panning 7 deg between frames (about 32 px at f = 262 px,
	// 210 deg/s at 30 Hz): frame t sees frame t-1's content through the
	// homography, cur(u) = prev(H u).
	const auto cam = test::vgaCamera(320, 240);
	const cv::Mat prev = test::texture(320, 240, 11);
	const mrpt::poses::CPose3D R(0, 0, 0, 0.02, 0.12, 0.01);
	const cv::Matx33d H = rotationHomography(cam, R);
	cv::Mat cur;
	cv::warpPerspective(prev, cur, H, prev.size(),
	                    cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
	                    cv::BORDER_REFLECT);
	const cv::Mat truth = homographyFlow(cam, R);

	FlowParams p;  // DIS fast, full resolution
	ObservedFlow of(p);
	const double plain = medianErrorAgainst(of.compute(prev, cur), truth, 8);
	// The egomotion's rotation is never exact: derotate with 0.3 deg off.
	const mrpt::poses::CPose3D Rest(0, 0, 0, 0.02 + 0.005, 0.12 - 0.003, 0.01);
	const cv::Mat der =
	    of.computeDerotated(prev, cur, rotationHomography(cam, Rest));
	ASSERT_EQ(der.type(), CV_32FC2);
	ASSERT_EQ(der.size(), cur.size());
	const double derotated = medianErrorAgainst(der, truth, 8);
	EXPECT_LT(derotated, 0.3);
	EXPECT_GT(plain, 3 * derotated) << "plain DIS " << plain << " px";
}

TEST(ObservedFlow, AutoPresetIsUltrafastOnVgaAndFastBelow)
{
	EXPECT_EQ(disPresetFor(DisPreset::Auto, 640), DisPreset::Ultrafast);
	EXPECT_EQ(disPresetFor(DisPreset::Auto, 639), DisPreset::Fast);
	EXPECT_EQ(disPresetFor(DisPreset::Auto, 320), DisPreset::Fast);
	EXPECT_EQ(disPresetFor(DisPreset::Medium, 640), DisPreset::Medium);
	EXPECT_EQ(disPresetFor(DisPreset::Fast, 1280), DisPreset::Fast);
	// and ObservedFlow runs that preset: the same flow, bit for bit, on the
	// images it is given (after downscale)
	auto flowWith = [](const std::string& preset, int w, int h, int ds)
	{
		FlowParams p;
		p.dis_preset = bims::parseChoice<DisPreset>(preset);
		p.downscale = ds;
		ObservedFlow of(p);
		const cv::Mat prev = test::texture(w, h, 3);
		return of.compute(prev, test::shifted(prev, 1.4, 0.6));
	};
	auto same = [](const cv::Mat& a, const cv::Mat& b)
	{ return a.size() == b.size() && cv::norm(a, b, cv::NORM_INF) == 0; };
	EXPECT_TRUE(same(flowWith("auto", 640, 480, 1),
	                 flowWith("ultrafast", 640, 480, 1)));
	EXPECT_FALSE(
	    same(flowWith("auto", 640, 480, 1), flowWith("fast", 640, 480, 1)));
	EXPECT_TRUE(
	    same(flowWith("auto", 320, 240, 1), flowWith("fast", 320, 240, 1)));
	EXPECT_TRUE(
	    same(flowWith("auto", 640, 480, 2), flowWith("fast", 640, 480, 2)));
	// an unknown preset is refused when the .ini is read, naming the key,
	// the value and the names
	mrpt::config::CConfigFileMemory bad(
	    std::string("[flow]\ndis_preset = quick\n"));
	try
	{
		FlowParams().loadFromConfigFile(bad);
		ADD_FAILURE() << "expected ConfigError";
	}
	catch (const bims::ConfigError& e)
	{
		EXPECT_NE(std::string(e.what()).find(
		              "[flow] dis_preset: 'quick' is not one of "
		              "auto|ultrafast|fast|medium"),
		          std::string::npos)
		    << e.what();
	}
}
