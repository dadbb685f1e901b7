// The depth correction: recovered from frames whose depth was distorted by a
// known smooth map, applied to images and observations, read strictly.
#include <bims/common/config.h>
#include <bims/ego/depth_correction.h>

#include <mrpt/config/CConfigFileMemory.h>

#include <gtest/gtest.h>

#include "synth_scene.h"

using namespace bims::ego;

namespace
{
using test::K320;

/** A distortion like the Bonn Kinect's: borders read short. */
DepthCorrectionParams trueCorrection()
{
	DepthCorrectionParams p;
	p.enable = true;
	p.coefficients = {0.005, 0.01, 0.08, 0.0, 0.06, 0, 0, 0, 0, 0, 0, 0};
	return p;
}

Eigen::Matrix4d pose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t)
{
	Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
	T.block<3, 3>(0, 0) = R;
	T.block<3, 1>(0, 3) = t;
	return T;
}
}  // namespace

TEST(DepthCorrection, FitRecoversAKnownDistortionFromAStaticStretch)
{
	test::Motion m;
	m.w_C = Eigen::Vector3d(0.1, 0.5, 0.05);
	m.v_W = Eigen::Vector3d(0.3, 0.3, 0.05);
	DepthCorrection truth(trueCorrection());
	std::vector<RgbdFrame> frames;
	std::vector<Eigen::Matrix4d> poses;
	for (int k = 0; k < 40; k++)
	{
		const double t = k * 0.05;
		RgbdFrame f = test::render(m.R(t), m.p(t), K320(), 320, 240, t);
		// the sensor reads z_true / (1 + delta)
		cv::divide(f.depth, truth.factors(f.K, f.depth.size()), f.depth);
		frames.push_back(f);
		poses.push_back(pose(m.R(t), m.p(t)));
	}
	DepthFitOptions o;
	o.samples_per_pair = 1500;
	const DepthFitResult r = estimateDepthCorrection(frames, poses, o);
	EXPECT_GT(r.pairs, 20);
	EXPECT_LT(r.rms_after_m, 0.5 * r.rms_before_m);
	// the correction where it matters (borders, corner) within 0.4 %
	DepthCorrection fit(r.params);
	const cv::Mat& ff = fit.factors(K320(), cv::Size(320, 240));
	const cv::Mat& ft = truth.factors(K320(), cv::Size(320, 240));
	for (const cv::Point p :
	     {cv::Point(0, 120), cv::Point(319, 120), cv::Point(160, 0),
	      cv::Point(160, 239), cv::Point(10, 10), cv::Point(160, 120)})
		EXPECT_NEAR(ff.at<float>(p), ft.at<float>(p), 0.004) << p;
	// with a wrong pose set the fit has nothing consistent to find
	std::vector<Eigen::Matrix4d> shifted = poses;
	for (auto& T : shifted) T.block<3, 1>(0, 3) *= 0;
	EXPECT_GT(estimateDepthCorrection(frames, shifted, o).rms_after_m,
	          2 * r.rms_after_m);
}

TEST(DepthCorrection, AppliesToAnObservationsRangeImage)
{
	mrpt::obs::CObservation3DRangeScan o;
	o.hasRangeImage = true;
	o.rangeUnits = 0.001f;
	o.rangeImage_setSize(240, 320);
	o.rangeImage.fill(2000);
	o.rangeImage(5, 5) = 0;  // no reading stays no reading
	CameraParams cam;
	cam.given = true;
	cam.fx = cam.fy = K320()(0, 0);
	cam.cx = 159.5;
	cam.cy = 119.5;
	cam.width = 320;
	cam.height = 240;
	DepthCorrection c(trueCorrection());
	c.apply(o, cam);
	EXPECT_EQ(o.rangeImage(5, 5), 0);
	const cv::Mat& f = c.factors(K320(), cv::Size(320, 240));
	EXPECT_EQ(o.rangeImage(120, 0), std::lround(2000 * f.at<float>(120, 0)));
	EXPECT_GT(o.rangeImage(120, 0), 2000 * 1.01);  // the border grew
	EXPECT_NEAR(o.rangeImage(120, 160), 2000, 1);  // the centre did not
	// disabled: untouched
	o.rangeImage.fill(2000);
	DepthCorrection off;
	off.apply(o, cam);
	EXPECT_EQ(o.rangeImage(120, 0), 2000);
}

TEST(DepthCorrection, ConfigIsReadStrictly)
{
	DepthCorrectionParams p;
	mrpt::config::CConfigFileMemory ok(std::string(
	    "[depth_correction]\nenable = true\ncoefficients = 0.1 0.2 0.3 0.4 0.5 "
	    "0.6 0.7 0.8 0.9 1 1.1 0.5\n"));
	p.loadFromConfigFile(ok);
	EXPECT_TRUE(p.enable);
	EXPECT_DOUBLE_EQ(p.coefficients[11], 0.5);
	// what bims-calib-depth writes reads back
	mrpt::config::CConfigFileMemory back(p.toIni("# test\n"));
	DepthCorrectionParams q;
	q.loadFromConfigFile(back);
	EXPECT_EQ(q.coefficients, p.coefficients);
	mrpt::config::CConfigFileMemory few(
	    std::string("[depth_correction]\ncoefficients = 1 2 3\n"));
	EXPECT_THROW(p.loadFromConfigFile(few), bims::ConfigError);
	mrpt::config::CConfigFileMemory typo(
	    std::string("[depth_correction]\nenabled = true\n"));
	EXPECT_THROW(p.loadFromConfigFile(typo), bims::ConfigError);
}

TEST(AnchorParams, OutOfRangeAndUnknownKeysAreErrors)
{
	for (const char* bad :
	     {"[anchor]\nstride_px = 0\n",
	      "[anchor]\ncoarsest_level = 1\nfinest_level = 2\n",
	      "[anchor]\nmax_depth_m = 0.2\n", "[anchor]\nstrides = 2\n",
	      "[anchor]\nmax_excluded_fraction = 1.5\n"})
	{
		mrpt::config::CConfigFileMemory c{std::string(bad)};
		AnchorParams p;
		EXPECT_THROW(p.loadFromConfigFile(c), bims::ConfigError) << bad;
	}
	AnchorParams p;
	mrpt::config::CConfigFileMemory good(
	    std::string("[anchor]\nenable = false\nstride_px = 2\n"));
	p.loadFromConfigFile(good);
	EXPECT_FALSE(p.enable);
	EXPECT_EQ(p.stride_px, 2);
}
