// End-to-end tests of bims-import-tum and bims-eval (run the built programs).
#include <bims/common/version.h>
#include <bims/eval/pose_utils.h>
#include <bims/eval/tum_import.h>
#include <bims/io/frame_files.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims_test/data.h>
#include <bims_test/png_bomb.h>
#include <bims_test/run_command.h>
#include <bims_test/text.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

namespace fs = std::filesystem;
namespace
{
const std::string kBin = BIMS_BIN_DIR;

using Run = bims::test::CommandResult;
Run run(const std::string& args)
{
	return bims::test::runCommand(args);
}
std::string tmpDir(const std::string& name)
{
	return bims::test::freshTmpDir("bims_test_eval", name);
}
std::string lastLine(const std::string& s)
{
	auto t = s;
	while (!t.empty() && t.back() == '\n') t.pop_back();
	return t.substr(t.rfind('\n') + 1);
}
}  // namespace

TEST(ImportTum, BonnTwentyFramesWithConvertedGroundTruth)
{
	if (!fs::exists(bims::test::kBonnCrowd + "/depth.txt"))
		GTEST_SKIP() << "no Bonn sample";
	const auto d = tmpDir("import");
	const auto r = run(kBin + "/bims-import-tum " + bims::test::kBonnCrowd +
	                   " -o " + d + "/b.rawlog --config " + BIMS_SOURCE_DIR +
	                   "/config/bonn.ini --max-frames 20 -q");
	ASSERT_EQ(r.code, 0) << r.out;
	const auto gt = bims::loadTumTrajectory(d + "/b_gt/groundtruth.txt");
	ASSERT_EQ(gt.size(), 20u);
	ASSERT_TRUE(fs::exists(d + "/b_gt/calibration.ini"));

	// The first scan: intrinsics, stamp, depth equal to the PNG (1 mm units).
	bims::RawlogReader rd(d + "/b.rawlog");
	size_t n = 0;
	mrpt::obs::CObservation3DRangeScan::Ptr first;
	while (auto o = rd.next())
		if (auto s =
		        std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
		            o))
		{
			if (!first) first = s;
			n++;
		}
	ASSERT_EQ(n, 20u);
	EXPECT_EQ(first->sensorLabel, "RGBD");
	EXPECT_NEAR(first->cameraParams.fx(), 542.822841, 1e-6);
	EXPECT_NEAR(first->cameraParams.cy(), 237.756098, 1e-6);
	EXPECT_NEAR(mrpt::Clock::toDouble(first->timestamp), 1548339824.89375,
	            1e-4);
	EXPECT_NEAR(gt[0].t, 1548339824.89375, 1e-5);
	const cv::Mat png =
	    cv::imread(bims::test::kBonnCrowd + "/depth/1548339824.89375.png",
	               cv::IMREAD_UNCHANGED);
	ASSERT_EQ(png.type(), CV_16UC1);
	size_t checked = 0;
	for (int v = 0; v < 480; v += 7)
		for (int u = 0; u < 640; u += 7)
		{
			const double expect = png.at<uint16_t>(v, u) / 5000.0;
			EXPECT_NEAR(first->rangeImage(v, u) * first->rangeUnits, expect,
			            5.1e-4);
			checked++;
		}
	EXPECT_GT(checked, 6000u);
	EXPECT_TRUE(first->hasIntensityImage);
	EXPECT_EQ(first->intensityImage.getWidth(), 640u);

	// GT vs itself through bims-eval: zero error, JSON and plot written.
	const auto e =
	    run(kBin + "/bims-eval traj " + d + "/b_gt/groundtruth.txt " + d +
	        "/b_gt/groundtruth.txt --delta 0.3 --json " + d + "/t.json -o " +
	        d + "/t.png");
	ASSERT_EQ(e.code, 0) << e.out;
	EXPECT_NE(e.out.find("ate_rmse 0.0000 m"), std::string::npos) << e.out;
	EXPECT_TRUE(fs::exists(d + "/t.png"));
	EXPECT_TRUE(fs::exists(d + "/t.json"));

	// Depth consistency of the converted poses on these frames (5 apart).
	const auto c = run(kBin + "/bims-eval depth-consistency " + d +
	                   "/b.rawlog " + d + "/b_gt/groundtruth.txt --gap 5");
	ASSERT_EQ(c.code, 0) << c.out;
	double med = 1, still = 0;
	ASSERT_EQ(
	    std::sscanf(
	        c.out.substr(c.out.find("median_abs_dz")).c_str(),
	        "median_abs_dz %lf m within_5cm %*f no_motion_median_abs_dz %lf",
	        &med, &still),
	    2)
	    << c.out;
	EXPECT_LT(med, 0.03) << c.out;
	EXPECT_GT(still, 1.5 * med) << c.out;

	// Masks over valid depth only: scan 5 of the rawlog is frame 5 of the
	// folder; GT = left half moving, prediction = everything moving.
	bims::eval::ImportParams ip;
	const auto folder = bims::eval::readTumFolder(bims::test::kBonnCrowd, ip);
	const cv::Mat d5 =
	    cv::imread(folder.frames[5].depthPath, cv::IMREAD_UNCHANGED);
	ASSERT_FALSE(d5.empty());
	const cv::Mat valid5 = d5 > 0;
	const cv::Mat left = valid5(cv::Rect(0, 0, 320, 480));
	const long nValid = cv::countNonZero(valid5),
	           nLeft = cv::countNonZero(left);
	fs::create_directories(d + "/gtm");
	fs::create_directories(d + "/predm");
	cv::Mat g(480, 640, CV_8UC1, cv::Scalar(0));
	g(cv::Rect(0, 0, 320, 480)) = 255;
	cv::imwrite(d + "/gtm/000005.png", g);
	cv::imwrite(d + "/predm/000005.png",
	            cv::Mat(480, 640, CV_8UC1, cv::Scalar(255)));
	const auto m = run(kBin + "/bims-eval masks " + d + "/gtm " + d +
	                   "/predm --depth-valid " + d + "/b.rawlog");
	ASSERT_EQ(m.code, 0) << m.out;
	char expect[128];
	std::snprintf(expect, sizeof(expect), "tp %ld fp %ld fn 0 tn 0 invalid %ld",
	              nLeft, nValid - nLeft, 640L * 480L - nValid);
	EXPECT_NE(m.out.find(expect), std::string::npos) << expect << "\n" << m.out;
	EXPECT_TRUE(fs::exists(d + "/predm_eval/000005.png"));
	// A mask index beyond the rawlog's scans is an error naming the rawlog.
	cv::imwrite(d + "/gtm/000050.png", g);
	cv::imwrite(d + "/predm/000050.png", g);
	const auto m2 = run(kBin + "/bims-eval masks " + d + "/gtm " + d +
	                    "/predm --no-plots --depth-valid " + d + "/b.rawlog");
	EXPECT_EQ(m2.code, 1);
	EXPECT_NE(m2.out.find("b.rawlog: has only 20 3D scans"), std::string::npos)
	    << m2.out;
}

TEST(ImportTum, BadInputIsAClearError)
{
	const auto d = tmpDir("import_bad");
	auto r =
	    run(kBin + "/bims-import-tum " + d + "/nothing -o " + d + "/x.rawlog");
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("nothing: not a directory"), std::string::npos)
	    << r.out;
	// Malformed rgb.txt line.
	{
		std::ofstream(d + "/rgb.txt") << "# c\n1.0 rgb/a.png\nfoo\n";
		std::ofstream(d + "/depth.txt") << "1.0 depth/a.png\n";
	}
	r = run(kBin + "/bims-import-tum " + d + " -o " + d + "/x.rawlog");
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("rgb.txt:3: expected 'timestamp filename'"),
	          std::string::npos)
	    << r.out;
	// Missing image.
	std::ofstream(d + "/rgb.txt") << "1.0 rgb/a.png\n";
	r = run(kBin + "/bims-import-tum " + d + " -o " + d + "/x.rawlog -q");
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("depth/a.png: cannot read depth image"),
	          std::string::npos)
	    << r.out;
	// Unknown key in the config.
	std::ofstream(d + "/c.ini")
	    << "[camera]\nfx = 500\nfy = 500\ncx = 320\ncy = 240\n"
	       "width = 640\nheight = 480\nfxx = 3\n";
	r = run(kBin + "/bims-import-tum " + d + " -o " + d +
	        "/x.rawlog --config " + d + "/c.ini");
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("fxx"), std::string::npos) << r.out;
}

TEST(EvalMasks, HandComputedTotalsAndErrors)
{
	const auto d = tmpDir("masks");
	fs::create_directories(d + "/gt");
	fs::create_directories(d + "/pred");
	// Frame 0: gt left half moving, pred left quarter: TP 4x8=32... on 8x8:
	// gt cols 0-3 (32 px), pred cols 0-1 (16 px): TP 16, FP 0, FN 16.
	// Frame 1: gt nothing, pred one column (8 px): FP 8.
	// Total: TP 16, FP 8, FN 16 -> P 16/24, R 0.5, F1 32/56, IoU 16/40.
	cv::Mat g0(8, 8, CV_8UC1, cv::Scalar(0)), p0 = g0.clone(), g1 = g0.clone(),
	                                          p1 = g0.clone();
	g0(cv::Rect(0, 0, 4, 8)) = 255;
	p0(cv::Rect(0, 0, 2, 8)) = 255;
	p1(cv::Rect(7, 0, 1, 8)) = 255;
	cv::imwrite(d + "/gt/000000.png", g0);
	cv::imwrite(d + "/pred/000000.png", p0);
	cv::imwrite(d + "/gt/000001.png", g1);
	cv::imwrite(d + "/pred/000001.png", p1);
	auto r = run(kBin + "/bims-eval masks " + d + "/gt " + d + "/pred");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_EQ(lastLine(r.out),
	          "total precision 0.6667 recall 0.5000 F1 0.5714 IoU 0.4000")
	    << r.out;
	EXPECT_TRUE(fs::exists(d + "/pred_eval/000001.png"));
	// frame 1 labels nothing moving: 8 of its 64 static pixels called moving
	EXPECT_NE(r.out.find("total_nothing_moving frames 1 static_as_moving "
	                     "0.1250"),
	          std::string::npos)
	    << r.out;
	// The overlays of that evaluation are not mixed with another's: refused
	// before any work, then replaced with --overwrite (other files stay).
	std::ofstream(d + "/pred_eval/notes.txt") << "mine";
	r = run(kBin + "/bims-eval masks " + d + "/gt " + d + "/pred");
	EXPECT_EQ(r.code, 2) << r.out;
	EXPECT_NE(r.out.find(d + "/pred_eval: holds the outputs of an earlier run "
	                         "(2 files, e.g. 000000.png); give --overwrite"),
	          std::string::npos)
	    << r.out;
	fs::remove(d + "/pred/000000.png");
	fs::remove(d + "/gt/000000.png");
	r = run(kBin + "/bims-eval masks " + d + "/gt " + d + "/pred --overwrite");
	EXPECT_EQ(r.code, 0) << r.out;
	EXPECT_FALSE(fs::exists(d + "/pred_eval/000000.png"));
	EXPECT_TRUE(fs::exists(d + "/pred_eval/000001.png"));
	EXPECT_TRUE(fs::exists(d + "/pred_eval/notes.txt"));
	cv::imwrite(d + "/gt/000000.png", g0);
	cv::imwrite(d + "/pred/000000.png", p0);
	// A mask of another size is an error naming both files.
	cv::imwrite(d + "/pred/000001.png", cv::Mat(4, 8, CV_8UC1, cv::Scalar(0)));
	r = run(kBin + "/bims-eval masks " + d + "/gt " + d + "/pred --no-plots");
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("000001.png: mask sizes differ"), std::string::npos)
	    << r.out;
	r = run(kBin + "/bims-eval masks " + d + "/gt " + d + "/missing");
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("missing: mask directory not found"),
	          std::string::npos)
	    << r.out;
	// The image limits (issue 39): a label declaring more than
	// --image-max-side / --image-max-pixels is refused before decoding,
	// naming it; the limits' ranges are checked.
	cv::imwrite(d + "/pred/000001.png", p1);
	r = run(kBin + "/bims-eval masks " + d + "/gt " + d +
	        "/pred --no-plots --image-max-side 7");
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_NE(r.out.find(d + "/gt/000000.png: cannot read mask image: "
	                         "declares 8 x 8 pixels in its PNG header, beyond "
	                         "the 7 per side"),
	          std::string::npos)
	    << r.out;
	r = run(kBin + "/bims-eval masks " + d + "/gt " + d +
	        "/pred --no-plots --image-max-pixels 63");
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_NE(r.out.find("and 63 pixels"), std::string::npos) << r.out;
	r = run(kBin + "/bims-eval masks " + d + "/gt " + d +
	        "/pred --no-plots --image-max-pixels 64 --image-max-side 8");
	EXPECT_EQ(r.code, 0) << r.out;
	r = run(kBin + "/bims-eval masks " + d + "/gt " + d +
	        "/pred --no-plots --image-max-side 0");
	EXPECT_EQ(r.code, 2) << r.out;
	EXPECT_NE(r.out.find("--image-max-side 0: out of range [1, 65535]"),
	          std::string::npos)
	    << r.out;
}

// Issue 55: labels named by index with frames missing in the middle were
// scored without them (exit 0, a higher F1, no note); as with labels named
// by time, a prediction inside the labels' span without its label is an
// error naming the missing labels, unless --sparse-labels.
TEST(EvalMasks, IndexNamedLabelsMissingInsideTheirSpanAreAnError)
{
	const auto d = tmpDir("missing_index_labels");
	fs::create_directories(d + "/gt");
	fs::create_directories(d + "/pred");
	cv::Mat g(8, 8, CV_8UC1, cv::Scalar(0)), p = g.clone();
	g(cv::Rect(0, 0, 4, 8)) = 255;
	p(cv::Rect(0, 0, 3, 8)) = 255;
	for (int k = 0; k < 12; ++k)  // predictions 0-11, labels 0-9
	{
		const std::string name = "/" + bims::frameFileName(k);
		cv::imwrite(d + "/pred" + name, p);
		if (k < 10) cv::imwrite(d + "/gt" + name, g);
	}
	auto r = run(kBin + "/bims-eval masks " + d + "/gt " + d +
	             "/pred --no-plots -q");
	ASSERT_EQ(r.code, 0) << r.out;  // (10, 11: a longer run, not scored)
	for (const char* gone : {"000003.png", "000004.png", "000008.png"})
		fs::remove(d + "/gt/" + gone);
	r = run(kBin + "/bims-eval masks " + d + "/gt " + d +
	        "/pred --no-plots -q");
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_NE(r.out.find(d +
	                     "/gt: no label of the same name for 3 "
	                     "prediction(s) of " +
	                     d +
	                     "/pred inside the labels' span (000000.png to "
	                     "000009.png): 000003.png, 000004.png, 000008.png: "
	                     "missing label frames? (--sparse-labels"),
	          std::string::npos)
	    << r.out;
	EXPECT_EQ(r.out.find("total precision"), std::string::npos) << r.out;
	r = run(kBin + "/bims-eval masks " + d + "/gt " + d +
	        "/pred --no-plots -q --sparse-labels");
	EXPECT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("5 predictions without a label (2 outside the "
	                     "labels' span), not scored"),
	          std::string::npos)
	    << r.out;
}

TEST(EvalMasks, LabelsByTimestampWithIgnoredValues)
{
	// A TUM/Bonn-style label folder (named by depth stamp; 255 moving, 0
	// static, 150 and 50 not scored) against a run's NNNNNN.png masks and
	// its frames.csv. Label 0 has no prediction (the importer dropped it).
	const auto d = tmpDir("masks_time");
	fs::create_directories(d + "/labels");
	fs::create_directories(d + "/run/masks");
	const char* names[] = {"100.00000", "100.03300", "100.06600", "100.09900"};
	for (const char* n : names)
	{
		// cols 0-1 moving, 2 ambiguous, 3 no depth, 4-7 static
		cv::Mat l(2, 8, CV_8UC1, cv::Scalar(0));
		l.colRange(0, 2) = 255;
		l.col(2) = 150;
		l.col(3) = 50;
		cv::imwrite(d + "/labels/" + n + ".png", l);
	}
	// predictions: cols 0 and 2-4 moving (TP 2, FP 2, FN 2 a frame)
	for (int k = 0; k < 3; k++)
	{
		cv::Mat p(2, 8, CV_8UC1, cv::Scalar(0));
		p.col(0) = 255;
		p.colRange(2, 5) = 255;
		cv::imwrite(d + "/run/masks/00000" + std::to_string(k) + ".png", p);
	}
	std::ofstream(d + "/run/frames.csv")
	    << "index,t,ego_flags\n0,100.033001,0\n1,100.066000,0\n2,100.099,0\n";
	const std::string conv =
	    " --moving-value 255 --static-value 0 --ignore-values 150,50";
	auto r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	             "/run/masks --no-plots --strip " + d + "/strip.png" +
	             " --strip-frames 0,2" + conv);
	ASSERT_EQ(r.code, 0) << r.out;
	// two overlays of 8x2 at half size side by side
	const cv::Mat strip = cv::imread(d + "/strip.png");
	EXPECT_EQ(strip.cols, 8);
	EXPECT_EQ(strip.rows, 1);
	// 3 frames: TP 6, FP 6, FN 6; 24 static pixels, 6 called moving
	EXPECT_EQ(lastLine(r.out),
	          "total precision 0.5000 recall 0.5000 F1 0.5000 IoU 0.3333")
	    << r.out;
	EXPECT_NE(r.out.find("total_static_as_moving 0.2500"), std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("ignored 12"), std::string::npos) << r.out;
	// (label 0 lies before the run's first frame: left out with a note)
	EXPECT_NE(r.out.find("note: 1 of 4 labels lie outside the run's frames"),
	          std::string::npos)
	    << r.out;
	// A label value outside the convention: a usage error before any
	// output, naming the value, the first label holding it and the counts.
	cv::Mat bad(2, 8, CV_8UC1, cv::Scalar(0));
	bad.at<uint8_t>(1, 5) = 77;
	cv::imwrite(d + "/labels/100.06600.png", bad);
	r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	        "/run/masks --no-plots" + conv);
	EXPECT_EQ(r.code, 2);
	EXPECT_NE(r.out.find("label values 77 (first in 100.06600.png) are "
	                     "neither moving"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("77: 1 px in 1 of 3 labels (UNKNOWN)"),
	          std::string::npos)
	    << r.out;
	// A label of another size.
	cv::imwrite(d + "/labels/100.06600.png",
	            cv::Mat(4, 8, CV_8UC1, cv::Scalar(0)));
	r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	        "/run/masks --no-plots" + conv);
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("mask sizes differ"), std::string::npos) << r.out;
	// A missing label frame inside the labels' span.
	fs::remove(d + "/labels/100.06600.png");
	r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	        "/run/masks --no-plots" + conv);
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("no label within 0.010000 s of prediction 000001.png"),
	          std::string::npos)
	    << r.out;
	r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	        "/run/masks --no-plots --sparse-labels" + conv);
	EXPECT_EQ(r.code, 0) << r.out;
	// Predictions of another run (stamps that do not match): no score.
	std::ofstream(d + "/run/frames.csv")
	    << "index,t\n0,200.033000\n1,200.066000\n2,200.099\n";
	r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	        "/run/masks --no-plots" + conv);
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("has a prediction within"), std::string::npos)
	    << r.out;
	EXPECT_EQ(r.out.find("total precision"), std::string::npos) << r.out;
	// No frames.csv beside the masks: says where it looked.
	fs::remove(d + "/run/frames.csv");
	r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	        "/run/masks --no-plots" + conv);
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("--frames-csv"), std::string::npos) << r.out;
	// A bad value list is a usage error naming it.
	r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	        "/run/masks --ignore-values 150,x");
	EXPECT_NE(r.code, 0);
	EXPECT_NE(r.out.find("'x' is not a label value"), std::string::npos)
	    << r.out;
}

TEST(EvalMasks, UndeclaredLabelValuesAreRefusedNotGuessed)
{
	// Bonn-proxy-style labels (255 moving, 0 static, 150 ambiguous, 50 no
	// depth) given without their convention: 150 must not be scored as
	// moving (it once was: >= 128). The evaluation refuses before any
	// output, listing each value and its counts; a labels.ini in the label
	// folder, or the options, declare them.
	const auto d = tmpDir("masks_undeclared");
	fs::create_directories(d + "/labels");
	fs::create_directories(d + "/pred");
	for (int k = 0; k < 2; k++)
	{
		// cols 0-1 moving (frame 1 only), 2 ambiguous, 3 no depth, 4-7 static
		cv::Mat l(2, 8, CV_8UC1, cv::Scalar(0));
		if (k == 1) l.colRange(0, 2) = 255;
		l.col(2) = 150;
		l.col(3) = 50;
		cv::imwrite(d + "/labels/00000" + std::to_string(k) + ".png", l);
		// prediction: cols 0-2 and 7 moving
		cv::Mat p(2, 8, CV_8UC1, cv::Scalar(0));
		p.colRange(0, 3) = 255;
		p.col(7) = 255;
		cv::imwrite(d + "/pred/00000" + std::to_string(k) + ".png", p);
	}
	auto r = run(kBin + "/bims-eval masks " + d + "/labels " + d + "/pred");
	EXPECT_EQ(r.code, 2) << r.out;
	EXPECT_NE(r.out.find("label values 50 (first in 000000.png),150 (first in "
	                     "000000.png) are neither moving, static nor not "
	                     "scored"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("150: 4 px in 2 of 2 labels (UNKNOWN)"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("255: 4 px in 1 of 2 labels (moving)"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("--ignore-values"), std::string::npos) << r.out;
	EXPECT_EQ(r.out.find("total precision"), std::string::npos) << r.out;
	EXPECT_FALSE(fs::exists(d + "/pred_eval")) << "no output before the check";
	// Declared in the folder: frame 0 has no moving label and reports its
	// false positives (cols 0, 1 and 7 of 2 rows), not F1 0; frame 1: TP 4,
	// FP 2 (col 7), FN 0.
	std::ofstream(d + "/labels/labels.ini")
	    << "[labels]\nmoving = 255\nstatic = 0\nnot_scored = 150 50\n";
	r = run(kBin + "/bims-eval masks " + d + "/labels " + d + "/pred");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("frame 000000 tp 0 fp 6 fn 0 no moving label: fp 6, "
	                     "static as moving 0.5000"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("labels: moving 255, static 0, not scored 150 50 (" +
	                     d + "/labels/labels.ini)"),
	          std::string::npos)
	    << r.out;
	EXPECT_EQ(lastLine(r.out),
	          "total precision 0.3333 recall 1.0000 F1 0.5000 IoU 0.3333")
	    << r.out;
	// A bad convention file is an error naming it.
	std::ofstream(d + "/labels/labels.ini")
	    << "[labels]\nmoving = 255\nstatic = 0\nnotscored = 150 50\n";
	r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	        "/pred --overwrite");
	EXPECT_NE(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("labels.ini"), std::string::npos) << r.out;
	EXPECT_NE(r.out.find("notscored"), std::string::npos) << r.out;
}

TEST(EvalTraj, BonnMarkerPosesAreWarnedAboutAndTheImportSaysSo)
{
	if (!fs::exists(bims::test::kBonnCrowd + "/depth.txt"))
		GTEST_SKIP() << "no Bonn sample";
	// Imported without -c: the marker's poses are kept, with a note.
	const auto d = tmpDir("bonn_marker");
	auto r = run(kBin + "/bims-import-tum " + bims::test::kBonnCrowd + " -o " +
	             d + "/m.rawlog --max-frames 80 -q");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("looks like a Bonn RGB-D Dynamic folder"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("-c bonn.ini or --bonn-gt"), std::string::npos)
	    << r.out;
	// The camera's poses as the estimate, the marker's as the "ground
	// truth": a small ATE, an RPE ten times too large: a warning naming
	// the cause and the fix.
	auto marker = bims::loadTumTrajectory(d + "/m_gt/groundtruth.txt");
	auto cam = marker;
	for (auto& p : cam) p.T_WC = bims::eval::bonnMarkerToCamera(p.T_WC);
	bims::saveTumTrajectory(d + "/cam.txt", cam);
	r = run(kBin + "/bims-eval traj " + d + "/m_gt/groundtruth.txt " + d +
	        "/cam.txt --no-plot");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("warning: the RPE"), std::string::npos) << r.out;
	EXPECT_NE(r.out.find("motion-capture marker"), std::string::npos) << r.out;
	EXPECT_NE(r.out.find("--bonn-gt"), std::string::npos) << r.out;
	// The camera's poses against themselves shifted by 2 ms: no warning.
	auto shifted = cam;
	for (auto& p : shifted) p.t += 0.002;
	bims::saveTumTrajectory(d + "/shifted.txt", shifted);
	r = run(kBin + "/bims-eval traj " + d + "/cam.txt " + d +
	        "/shifted.txt --no-plot");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out;
	// Imported with the Bonn preset: no note.
	r = run(kBin + "/bims-import-tum " + bims::test::kBonnCrowd + " -o " + d +
	        "/c.rawlog --max-frames 10 -q -c " + BIMS_SOURCE_DIR +
	        "/config/bonn.ini");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_EQ(r.out.find("looks like a Bonn"), std::string::npos) << r.out;
}

TEST(EvalMasks, APartialRunIsScoredAgainstTheLabelsOfItsFrames)
{
	// 20 labels named by time; a run of frames 5-12 of them (bims-run
	// --frames 5:12 numbers its masks by scan index, frames.csv gives
	// their stamps): scored against those 8 labels, the 12 others left out
	// with a note, not refused as "only 8 of the 20 labels".
	const auto d = tmpDir("masks_span");
	fs::create_directories(d + "/labels");
	fs::create_directories(d + "/run/masks");
	std::ofstream csv(d + "/run/frames.csv");
	csv << "index,t\n";
	for (int k = 0; k < 20; k++)
	{
		cv::Mat l(2, 4, CV_8UC1, cv::Scalar(0));
		l.col(0) = 255;
		char name[64];
		std::snprintf(name, sizeof name, "%.5f", 100 + 0.03 * k);
		cv::imwrite(d + "/labels/" + name + ".png", l);
		if (k < 5 || k > 12) continue;
		cv::Mat p(2, 4, CV_8UC1, cv::Scalar(0));
		p.colRange(0, 2) = 255;  // TP 2, FP 2
		cv::imwrite(d + "/run/masks/" + bims::frameFileName(k), p);
		csv << k << "," << name << "\n";
	}
	csv.close();
	auto r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	             "/run/masks --no-plots");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("note: 12 of 20 labels lie outside the run's frames "
	                     "(100.15000.png to 100.36000.png), not scored"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("total_counts frames 8 tp 16 fp 16 fn 0"),
	          std::string::npos)
	    << r.out;
	EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out;
	// --span labels: every label must have a prediction.
	r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	        "/run/masks --no-plots --span labels");
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_NE(r.out.find("only 8 of the 20 labels"), std::string::npos)
	    << r.out;
	r = run(kBin + "/bims-eval masks " + d + "/labels " + d +
	        "/run/masks --no-plots --span all");
	EXPECT_EQ(r.code, 2) << r.out;
}

TEST(EvalTraj, BadInputIsAClearError)
{
	const auto d = tmpDir("traj");
	std::ofstream(d + "/gt.txt")
	    << "1 0 0 0 0 0 0 1\n2 1 0 0 0 0 0 1\n3 2 0 0 0 0 0 1\n";
	std::ofstream(d + "/empty.txt") << "# nothing\n";
	std::ofstream(d + "/bad.txt") << "1 0 0 0 0 0 0 1\n2 0 0\n";
	std::ofstream(d + "/late.txt")
	    << "101 0 0 0 0 0 0 1\n102 1 0 0 0 0 0 1\n103 2 0 0 0 0 0 1\n";
	auto r = run(kBin + "/bims-eval traj " + d + "/gt.txt " + d + "/empty.txt");
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("empty.txt: trajectory is empty"), std::string::npos)
	    << r.out;
	r = run(kBin + "/bims-eval traj " + d + "/gt.txt " + d + "/bad.txt");
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("bad.txt:2:"), std::string::npos) << r.out;
	r = run(kBin + "/bims-eval traj " + d + "/gt.txt " + d +
	        "/late.txt --no-plot");
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("no time overlap"), std::string::npos) << r.out;
	r = run(kBin + "/bims-eval traj " + d + "/gt.txt " + d + "/nofile.txt");
	EXPECT_EQ(r.code, 1);
	EXPECT_NE(r.out.find("nofile.txt: file not found"), std::string::npos)
	    << r.out;
	r = run(kBin + "/bims-eval frobnicate");
	EXPECT_EQ(r.code, 2);
}

TEST(EvalTraj, AJumpIsReportedWithItsFrameCountAndSpeed)
{
	// 0.5 m/s along x at 30 Hz; the estimate 5 cm off along y from frame 20
	const auto d = tmpDir("traj_jump");
	std::ofstream gt(d + "/gt.txt"), est(d + "/est.txt");
	for (int k = 0; k <= 30; k++)
	{
		char g[128], e[128];
		const double t = 10 + k / 30.0;
		std::snprintf(g, sizeof(g), "%.9f %.9f 0 1 0 0 0 1\n", t, 0.5 * k / 30);
		std::snprintf(e, sizeof(e), "%.9f %.9f %.2f 1 0 0 0 1\n", t,
		              0.5 * k / 30, k >= 20 ? 0.05 : 0.0);
		gt << g;
		est << e;
	}
	gt.close();
	est.close();
	const std::string cmd = kBin + "/bims-eval traj " + d + "/gt.txt " + d +
	                        "/est.txt --no-plot --json " + d + "/t.json";
	auto r = run(cmd);
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("\nmax_frame_trans_err 0.0500 m (at t 10.666667, "
	                     "est pose 20;"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("\nframes_over_jump 1 (of 30 frame pairs, error > "
	                     "0.030 m)"),
	          std::string::npos)
	    << r.out;
	// |(0.5 / 30, 0.05)| * 30 = 1.5811 m/s
	EXPECT_NE(r.out.find("\nmax_speed 1.5811 m/s (at t 10.666667, est pose "
	                     "20; reference 0.5000 m/s there)"),
	          std::string::npos)
	    << r.out;
	const auto json = bims::test::fileText(d + "/t.json");
	EXPECT_NE(json.find("\"frames_over_jump\": 1"), std::string::npos) << json;
	EXPECT_NE(json.find("\"max_est_index\": 20"), std::string::npos) << json;
	r = run(cmd + " --jump-m 0.06");
	EXPECT_NE(r.out.find("\nframes_over_jump 0 "), std::string::npos) << r.out;
	r = run(cmd + " --jump-m -1");
	EXPECT_EQ(r.code, 2) << r.out;
	EXPECT_NE(r.out.find("--jump-m must be >= 0"), std::string::npos) << r.out;
	// the trajectory against itself: no jump
	r = run(kBin + "/bims-eval traj " + d + "/gt.txt " + d +
	        "/gt.txt --no-plot");
	EXPECT_NE(r.out.find("\nmax_frame_trans_err 0.0000 m"), std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("\nframes_over_jump 0 "), std::string::npos) << r.out;
}

TEST(ImportTum, SynthImuFromConvertedGroundTruthSeesGravityUp)
{
	// Synthetic IMU from the converted Bonn poses: the world must be z up
	// for the accelerometer to read gravity on the IMU's up axis ({I} = MRPT
	// scan frame by default: z up when the camera is level).
	if (!fs::exists(bims::test::kBonnCrowd + "/depth.txt"))
		GTEST_SKIP() << "no Bonn sample";
	const auto d = tmpDir("synth");
	const auto r = run(kBin + "/bims-import-tum " + bims::test::kBonnCrowd +
	                   " -o " + d + "/s.rawlog --config " + BIMS_SOURCE_DIR +
	                   "/config/bonn.ini --max-frames 30 --synth-imu -q");
	if (r.code == 2 && r.out.find("no simulator library") != std::string::npos)
		GTEST_SKIP() << r.out;
	ASSERT_EQ(r.code, 0) << r.out;
	bims::RawlogReader rd(d + "/s.rawlog");
	size_t n = 0;
	double sumNorm = 0, sumZ = 0;
	while (auto o = rd.next())
		if (auto m = std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o))
		{
			EXPECT_EQ(m->sensorLabel, "IMU_SYNTH");
			const double ax = m->get(mrpt::obs::IMU_X_ACC),
			             ay = m->get(mrpt::obs::IMU_Y_ACC),
			             az = m->get(mrpt::obs::IMU_Z_ACC);
			sumNorm += std::sqrt(ax * ax + ay * ay + az * az);
			sumZ += az;
			n++;
		}
	// 30 frames ~ 0.97 s at 100 Hz.
	EXPECT_GT(n, 80u);
	EXPECT_LT(n, 110u);
	EXPECT_NEAR(sumNorm / n, 9.8, 0.6);
	EXPECT_GT(sumZ / n, 8.5);
}

TEST(ImportParams, BonnIniAndStrictKeys)
{
	mrpt::config::CConfigFile cfg(std::string(BIMS_SOURCE_DIR) +
	                              "/config/bonn.ini");
	bims::eval::ImportParams p;
	p.loadFromConfigFile(cfg);
	EXPECT_DOUBLE_EQ(p.camera.fx, 542.822841);
	EXPECT_DOUBLE_EQ(p.camera.cy, 237.756098);
	EXPECT_DOUBLE_EQ(p.camera.depthScale, 5000);
	EXPECT_TRUE(p.bonnGt);
	EXPECT_EQ(p.imuLabel, "IMU_SYNTH");
	EXPECT_DOUBLE_EQ(p.rangeUnits, 0.001);

	mrpt::config::CConfigFileMemory bad("[import]\nmax_time_gap = 0.02\n");
	try
	{
		bims::eval::ImportParams q;
		q.loadFromConfigFile(bad);
		FAIL();
	}
	catch (const std::exception& e)
	{
		EXPECT_NE(std::string(e.what()).find("max_time_gap"), std::string::npos)
		    << e.what();
	}
	// depth_scale in the other convention (metres per unit) is refused.
	mrpt::config::CConfigFileMemory inv("[camera]\ndepth_scale = 0.001\n");
	try
	{
		bims::eval::ImportParams q;
		q.loadFromConfigFile(inv);
		FAIL();
	}
	catch (const std::exception& e)
	{
		EXPECT_NE(std::string(e.what()).find("value per metre"),
		          std::string::npos)
		    << e.what();
	}
	mrpt::config::CConfigFileMemory range("[import]\ntimestamp = both\n");
	bims::eval::ImportParams q;
	EXPECT_THROW(q.loadFromConfigFile(range), std::exception);
}

TEST(Apps, HelpExitsCleanlyAndBadOptionsExitWithCodeTwo)
{
	// MRPT's TCLAP prints --help and parse errors and returns instead of
	// exiting: no program may go on with empty arguments after them.
	for (const std::string app :
	     {"bims-run", "bims-odom", "bims-sim", "bims-import-tum",
	      "bims-import-stray", "bims-import-bag", "bims-flow-check",
	      "bims-flow-labels", "bims-calib-imu", "bims-calib-depth", "bims-info",
	      "bims-maps-figure", "bims-grab", "bims-sweep", "bims-eval masks",
	      "bims-eval traj", "bims-eval depth-consistency"})
	{
		if (!fs::exists(kBin + "/" + app.substr(0, app.find(' '))))
			continue;  // bims-grab without OpenNI2
		const ::Run v = run(kBin + "/" + app + " --version");
		EXPECT_EQ(v.code, 0) << app << "\n" << v.out;
		EXPECT_NE(v.out.find(bims::version()), std::string::npos) << app;
		const ::Run h = run(kBin + "/" + app + " --help");
		EXPECT_EQ(h.code, 0) << app << "\n" << h.out;
		EXPECT_NE(h.out.find("USAGE"), std::string::npos) << app;
		EXPECT_EQ(h.out.find("error"), std::string::npos) << app << "\n"
		                                                  << h.out;
		const ::Run b = run(kBin + "/" + app + " --no-such-option");
		EXPECT_EQ(b.code, 2) << app << "\n" << b.out;
		EXPECT_NE(b.out.find("usage error: unknown option '--no-such-option'"),
		          std::string::npos)
		    << app << "\n"
		    << b.out;
	}
	const ::Run v = run(kBin + "/bims-eval --version");
	EXPECT_EQ(v.code, 0) << v.out;
	EXPECT_NE(v.out.find(bims::version()), std::string::npos) << v.out;
}

TEST(Apps, AMistypedOptionIsAnErrorBeforeAnyWork)
{
	// bims-run takes several inputs: TCLAP alone took "--frmes" for one,
	// ran the whole first input and only then failed on "no such file"
	const auto d = tmpDir("typo");
	const std::string sample =
	    std::string(BIMS_SOURCE_DIR) + "/rawlogs/pendulum_slow.rawlog";
	const std::string cfg =
	    std::string(BIMS_SOURCE_DIR) + "/config/default.ini";
	const ::Run r = run(kBin + "/bims-run " + cfg + " " + sample +
	                    " --frmes 1:3 -o " + d + "/out");
	EXPECT_EQ(r.code, 2) << r.out;
	EXPECT_NE(r.out.find("unknown option '--frmes' (did you mean --frames?)"),
	          std::string::npos)
	    << r.out;
	EXPECT_FALSE(fs::exists(d + "/out"));
	// a value that looks like an option is still a value; "-q -o" combined
	// switches are not, and negative numbers are values
	const ::Run v = run(kBin + "/bims-run " + cfg + " " + sample +
	                    " --frames 0:1 -qo " + d + "/out2");
	EXPECT_EQ(v.code, 2) << v.out;
	EXPECT_NE(v.out.find("unknown option '-qo'"), std::string::npos) << v.out;
	const ::Run eq = run(kBin + "/bims-run " + cfg + " " + sample +
	                     " --frames=0:1 -o " + d + "/out3");
	EXPECT_EQ(eq.code, 2) << eq.out;
	EXPECT_NE(eq.out.find("'--frames=0:1': give the value after a space "
	                      "(--frames 0:1)"),
	          std::string::npos)
	    << eq.out;
	const ::Run ok =
	    run(kBin + "/bims-eval traj " + cfg + " " + cfg + " --offset -0.5");
	EXPECT_EQ(ok.out.find("unknown option"), std::string::npos) << ok.out;
	EXPECT_FALSE(fs::exists(d + "/out2") || fs::exists(d + "/out3"));
}

TEST(ImportTum, AFailedImportLeavesNoRawlogUnderItsName)
{
	// frame 1 imports, frame 2's depth image is missing: the rawlog was
	// half written when the import failed
	const auto d = tmpDir("import_partial");
	fs::create_directories(d + "/rgb");
	fs::create_directories(d + "/depth");
	ASSERT_TRUE(cv::imwrite(d + "/rgb/a.png",
	                        cv::Mat(480, 640, CV_8UC3, cv::Scalar(9, 9, 9))));
	ASSERT_TRUE(cv::imwrite(d + "/depth/a.png",
	                        cv::Mat(480, 640, CV_16UC1, cv::Scalar(5000))));
	ASSERT_TRUE(cv::imwrite(d + "/rgb/b.png",
	                        cv::Mat(480, 640, CV_8UC3, cv::Scalar(9, 9, 9))));
	std::ofstream(d + "/rgb.txt") << "1.0 rgb/a.png\n1.1 rgb/b.png\n";
	std::ofstream(d + "/depth.txt") << "1.0 depth/a.png\n1.1 depth/b.png\n";
	const std::string out = d + "/x.rawlog";
	const auto r =
	    run(kBin + "/bims-import-tum " + d + " -o " + out + " --gz 0 -q");
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_NE(r.out.find("depth/b.png: cannot read depth image"),
	          std::string::npos)
	    << r.out;
	EXPECT_FALSE(fs::exists(out));
	EXPECT_FALSE(fs::exists(out + ".partial"));
	// the same folder whole: the rawlog under its name, no partial file
	ASSERT_TRUE(cv::imwrite(d + "/depth/b.png",
	                        cv::Mat(480, 640, CV_16UC1, cv::Scalar(5000))));
	const auto ok =
	    run(kBin + "/bims-import-tum " + d + " -o " + out + " --gz 0 -q");
	EXPECT_EQ(ok.code, 0) << ok.out;
	EXPECT_GT(fs::file_size(out), 0u);
	EXPECT_FALSE(fs::exists(out + ".partial"));
	EXPECT_TRUE(fs::exists(d + "/x_gt/calibration.ini"));
	EXPECT_FALSE(fs::exists(d + "/x_gt.partial"));
}

// Issue 39's reproduction: bims-import-tum -c read its .ini without the
// strict reader (exit 0 with the TUM default camera for a binary, empty or
// BOM file, duplicate keys, a [camera] with only fx; a raw MRPT exception
// for a folder). Each is now an error naming the file.
TEST(ImportTum, TheConfigIsReadStrictly)
{
	const auto d = tmpDir("import_strict_ini");
	fs::create_directories(d + "/rgb");
	fs::create_directories(d + "/depth");
	ASSERT_TRUE(cv::imwrite(d + "/rgb/a.png",
	                        cv::Mat(48, 64, CV_8UC3, cv::Scalar(9, 9, 9))));
	ASSERT_TRUE(cv::imwrite(d + "/depth/a.png",
	                        cv::Mat(48, 64, CV_16UC1, cv::Scalar(5000))));
	std::ofstream(d + "/rgb.txt") << "1.0 rgb/a.png\n";
	std::ofstream(d + "/depth.txt") << "1.0 depth/a.png\n";
	fs::create_directories(d + "/cfg_dir");
	const std::vector<std::pair<std::string, std::string>> cases = {
	    {std::string("\x7f\x45\x4c\x46\x02\x01\x01\x00", 8), "binary bytes"},
	    {"", "no settings at all"},
	    {"\xEF\xBB\xBF[camera]\nfx = 50\n", "byte-order mark"},
	    {"[camera]\nfx = 50\nfx = 51\n", "fx given twice"},
	    {"[camera]\nfx = 50\n",
	     "all or none; given: fx, missing: fy cx cy "
	     "width height"},
	};
	int k = 0;
	for (const auto& [text, want] : cases)
	{
		const std::string ini = d + "/c" + std::to_string(k++) + ".ini";
		std::ofstream(ini, std::ios::binary) << text;
		const auto r = run(kBin + "/bims-import-tum " + d + " -o " + d +
		                   "/x.rawlog -q -c " + ini);
		EXPECT_EQ(r.code, 1) << r.out;
		EXPECT_NE(r.out.find(ini + ":"), std::string::npos) << r.out;
		EXPECT_NE(r.out.find(want), std::string::npos) << r.out;
		EXPECT_FALSE(fs::exists(d + "/x.rawlog")) << r.out;
	}
	const auto r = run(kBin + "/bims-import-tum " + d + " -o " + d +
	                   "/x.rawlog -c " + d + "/cfg_dir");
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_NE(r.out.find("cfg_dir: not a regular file"), std::string::npos)
	    << r.out;
	EXPECT_EQ(r.out.find("backtrace"), std::string::npos) << r.out;
}

// Issue 39's reproduction: a failed import left OUT_gt/ with the new
// ground truth beside the old rawlog. Now the earlier pair stays whole.
TEST(ImportTum, AFailedImportLeavesTheEarlierRawlogAndGroundTruthTogether)
{
	const auto d = tmpDir("import_gt_pair");
	fs::create_directories(d + "/rgb");
	fs::create_directories(d + "/depth");
	std::string rgbTxt, depthTxt, gtTxt;
	for (int i = 0; i < 3; ++i)
	{
		const std::string n = std::to_string(i) + ".png";
		const std::string t = "1." + std::to_string(i);
		ASSERT_TRUE(cv::imwrite(d + "/rgb/" + n,
		                        cv::Mat(48, 64, CV_8UC3, cv::Scalar(9, 9, 9))));
		ASSERT_TRUE(cv::imwrite(d + "/depth/" + n,
		                        cv::Mat(48, 64, CV_16UC1, cv::Scalar(5000))));
		rgbTxt += t + " rgb/" + n + "\n";
		depthTxt += t + " depth/" + n + "\n";
		gtTxt += t + " " + std::to_string(0.1 * i) + " 0 0 0 0 0 1\n";
	}
	std::ofstream(d + "/rgb.txt") << rgbTxt;
	std::ofstream(d + "/depth.txt") << depthTxt;
	std::ofstream(d + "/groundtruth.txt") << gtTxt;
	std::ofstream(d + "/cam.ini") << "[camera]\nfx = 50\nfy = 50\ncx = 32\n"
	                                 "cy = 24\nwidth = 64\nheight = 48\n"
	                                 "depth_scale = 5000\n";
	const std::string out = d + "/k.rawlog";
	const std::string cmd = kBin + "/bims-import-tum " + d + " -o " + out +
	                        " -c " + d + "/cam.ini -q";
	auto r = run(cmd + " --max-frames 2");
	ASSERT_EQ(r.code, 0) << r.out;
	const auto gt = [&]
	{ return bims::test::fileText(d + "/k_gt/groundtruth.txt"); };
	const std::string rawlogBefore = bims::test::fileText(out), gtBefore = gt();
	ASSERT_EQ(bims::loadTumTrajectory(d + "/k_gt/groundtruth.txt").size(), 2u);
	// all three frames, the third's depth image broken: the import fails
	std::ofstream(d + "/depth/2.png") << "not a png";
	r = run(cmd);
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_EQ(bims::test::fileText(out), rawlogBefore);
	EXPECT_EQ(gt(), gtBefore) << "a new ground truth beside the old rawlog";
	EXPECT_FALSE(fs::exists(d + "/k_gt.partial"));
	// whole again: both replaced together
	ASSERT_TRUE(cv::imwrite(d + "/depth/2.png",
	                        cv::Mat(48, 64, CV_16UC1, cv::Scalar(5000))));
	r = run(cmd);
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_EQ(bims::loadTumTrajectory(d + "/k_gt/groundtruth.txt").size(), 3u);
}

// Issue 39's reproduction: a PNG of ~100 bytes declaring 30000 x 30000
// RGBA 16-bit took 7.1 GB in bims-import-tum (as a depth image) and
// bims-eval masks (as a label); both refuse it from its header now.
TEST(Apps, ADecompressionBombIsRefusedFromItsHeader)
{
	const auto d = tmpDir("png_bomb");
	fs::create_directories(d + "/rgb");
	fs::create_directories(d + "/depth");
	ASSERT_TRUE(cv::imwrite(d + "/rgb/a.png",
	                        cv::Mat(480, 640, CV_8UC3, cv::Scalar(9, 9, 9))));
	bims::test::writePngBomb(d + "/depth/a.png");
	std::ofstream(d + "/rgb.txt") << "1.0 rgb/a.png\n";
	std::ofstream(d + "/depth.txt") << "1.0 depth/a.png\n";
	auto r = run(kBin + "/bims-import-tum " + d + " -o " + d + "/x.rawlog -q");
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_NE(r.out.find("depth/a.png: cannot read depth image: declares "
	                     "30000 x 30000 pixels in its PNG header"),
	          std::string::npos)
	    << r.out;

	fs::create_directories(d + "/gt");
	fs::create_directories(d + "/pred");
	bims::test::writePngBomb(d + "/gt/000000.png");
	cv::imwrite(d + "/pred/000000.png", cv::Mat(8, 8, CV_8UC1, cv::Scalar(0)));
	r = run(kBin + "/bims-eval masks " + d + "/gt " + d + "/pred");
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_NE(r.out.find("gt/000000.png: cannot read mask image: declares "
	                     "30000 x 30000"),
	          std::string::npos)
	    << r.out;
}

TEST(Apps, NoProgramWritesOverItsInput)
{
	const auto d = tmpDir("aliases");
	// copies: a broken rule must not write over the source tree
	const std::string cfg = d + "/default.ini";
	fs::copy_file(std::string(BIMS_SOURCE_DIR) + "/config/default.ini", cfg);
	const std::string in = d + "/in.rawlog";
	fs::copy_file(
	    std::string(BIMS_SOURCE_DIR) + "/rawlogs/pendulum_slow.rawlog", in);
	const auto size = fs::file_size(in);
	std::ofstream(d + "/gt.txt") << "1 0 0 0 0 0 0 1\n";
	fs::create_symlink(in, d + "/link.rawlog");
	for (const std::string& args :
	     {"bims-odom " + cfg + " " + in + " -o " + in,
	      "bims-odom " + cfg + " " + in + " -o " + d + "/link.rawlog",
	      "bims-odom " + cfg + " " + in + " -o " + d + "/t.txt --csv " + in,
	      "bims-odom " + cfg + " " + in + " -o ''",
	      "bims-calib-depth " + cfg + " " + in + " -o " + in,
	      "bims-calib-imu " + cfg + " " + in + " -o " + cfg,
	      "bims-eval traj " + d + "/gt.txt " + d + "/gt.txt --json " + d +
	          "/gt.txt",
	      "bims-sim " + cfg + " -o " + cfg,
	      "bims-import-tum " + d + " -o " + d + "/../aliases",
	      "bims-import-stray " + d + " -o " + d + "/../aliases",
	      "bims-import-stray " + d + " -o " + cfg + " -c " + cfg,
	      "bims-import-stray " + d + " -o " + d + "/x.rawlog -c " + d +
	          "/x_arkit_reference.txt",
	      "bims-import-bag " + in + " -o " + in,
	      "bims-import-bag " + in + " -o " + d + "/x.rawlog -c " + d +
	          "/x.rawlog"})
	{
		const ::Run r = run(kBin + "/" + args);
		EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
		EXPECT_TRUE(r.out.find("would overwrite the input") !=
		                std::string::npos ||
		            r.out.find("contains the input") != std::string::npos ||
		            r.out.find("output path is empty") != std::string::npos)
		    << args << "\n"
		    << r.out;
	}
	// Issue 39's reproductions: a file of an input folder (a TUM folder's
	// rgb.txt, a mask of the masks evaluated or fed back) was written over
	// with exit 0
	fs::create_directories(d + "/tum/rgb");
	fs::create_directories(d + "/tum/depth");
	std::ofstream(d + "/tum/rgb.txt") << "1.0 rgb/a.png\n";
	std::ofstream(d + "/tum/depth.txt") << "1.0 depth/a.png\n";
	fs::create_directories(d + "/gt_masks");
	fs::create_directories(d + "/pred");
	for (const char* m :
	     {"/gt_masks/000000.png", "/pred/000000.png", "/pred/000001.png"})
		cv::imwrite(d + m, cv::Mat(8, 8, CV_8UC1, cv::Scalar(0)));
	const auto maskSize = fs::file_size(d + "/pred/000000.png");
	for (const std::string& args :
	     {"bims-import-tum " + d + "/tum -o " + d + "/tum/rgb.txt",
	      "bims-eval masks " + d + "/gt_masks " + d + "/pred --json " + d +
	          "/pred/000000.png",
	      "bims-eval masks " + d + "/gt_masks " + d + "/pred --strip " + d +
	          "/pred/000001.png",
	      "bims-odom " + cfg + " " + in + " --masks " + d + "/pred -o " + d +
	          "/pred/000000.png",
	      "bims-odom " + cfg + " " + in + " --masks " + d + "/pred -o " + d +
	          "/t.txt --csv " + d + "/pred/000001.png"})
	{
		const ::Run r = run(kBin + "/" + args);
		EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
		EXPECT_NE(r.out.find("would overwrite the input"), std::string::npos)
		    << args << "\n"
		    << r.out;
	}
	EXPECT_EQ(bims::test::fileText(d + "/tum/rgb.txt"), "1.0 rgb/a.png\n");
	EXPECT_EQ(fs::file_size(d + "/pred/000000.png"), maskSize);
	EXPECT_EQ(fs::file_size(d + "/pred/000001.png"), maskSize);
	if (fs::exists(kBin + "/bims-viewer"))  // built with the GUI
	{
		const ::Run r =
		    run(kBin + "/bims-viewer " + in + " --max-frames 3 --screenshot " +
		        d + "/link.rawlog");
		EXPECT_EQ(r.code, 2) << r.out;
		EXPECT_NE(r.out.find("would overwrite the input"), std::string::npos)
		    << r.out;
		// screenshots into a results folder's masks
		fs::create_directories(d + "/results/masks");
		std::ofstream(d + "/results/trajectory.txt") << "";
		cv::imwrite(d + "/results/masks/000000.png",
		            cv::Mat(8, 8, CV_8UC1, cv::Scalar(0)));
		const ::Run v =
		    run(kBin + "/bims-viewer " + in + " --results " + d +
		        "/results --png-sequence " + d +
		        "/results/masks --max-frames 2 --screenshot " + d + "/v.png");
		EXPECT_EQ(v.code, 2) << v.out;
		EXPECT_NE(v.out.find("contains the input"), std::string::npos) << v.out;
	}
	EXPECT_EQ(fs::file_size(in), size);
	EXPECT_EQ(fs::file_size(cfg), fs::file_size(std::string(BIMS_SOURCE_DIR) +
	                                            "/config/default.ini"));
}

// The IMU attitude of the bundled sample (bims-odom --attitude) against its
// ground truth (bims-eval attitude): the simulator's IMU, magnetometer
// included, gives a tilt well under a degree and no heading drift to speak
// of; bad axes and missing files are clear errors.
TEST(EvalAttitude, TheSampleImuAttitudeAgainstItsGroundTruth)
{
	const auto d = tmpDir("attitude");
	const std::string sample =
	    std::string(BIMS_SOURCE_DIR) + "/rawlogs/pendulum_slow.rawlog";
	const std::string gt = std::string(BIMS_SOURCE_DIR) +
	                       "/rawlogs/pendulum_slow_gt/groundtruth.txt";
	const auto o =
	    run(kBin + "/bims-odom " + BIMS_SOURCE_DIR + "/config/default.ini " +
	        sample + " -o " + d + "/traj.txt --attitude " + d + "/att.txt -q");
	ASSERT_EQ(o.code, 0) << o.out;
	const auto att = bims::loadTumTrajectory(d + "/att.txt");
	const auto traj = bims::loadTumTrajectory(d + "/traj.txt");
	ASSERT_GT(att.size(), traj.size() - 3);
	for (const auto& p : att) EXPECT_EQ(p.T_WC.translation().norm(), 0);
	const auto r = run(kBin + "/bims-eval attitude " + gt + " " + d +
	                   "/att.txt --skip-s 1 --json " + d + "/att.json");
	ASSERT_EQ(r.code, 0) << r.out;
	double tilt = -1, drift = 1e9, headingMax = -1;
	std::sscanf(r.out.substr(r.out.find("tilt_rmse")).c_str(), "tilt_rmse %lf",
	            &tilt);
	std::sscanf(r.out.substr(r.out.find("heading_drift")).c_str(),
	            "heading_drift %lf deg/min (max |heading error| %lf", &drift,
	            &headingMax);
	EXPECT_GE(tilt, 0);
	EXPECT_LT(tilt, 1.0) << r.out;
	// (4 s: the slope of a heading that wanders by tenths of a degree)
	EXPECT_LT(std::abs(drift), 60) << r.out;
	EXPECT_GE(headingMax, 0);
	EXPECT_LT(headingMax, 2.0) << r.out;
	EXPECT_TRUE(fs::exists(d + "/att.json"));
	// the wrong up axis for the reference shows as a large tilt
	const auto w = run(kBin + "/bims-eval attitude " + gt + " " + d +
	                   "/att.txt --ref-up y");
	ASSERT_EQ(w.code, 0) << w.out;
	std::sscanf(w.out.substr(w.out.find("tilt_rmse")).c_str(), "tilt_rmse %lf",
	            &tilt);
	EXPECT_GT(tilt, 30) << w.out;
	const auto bad = run(kBin + "/bims-eval attitude " + gt + " " + d +
	                     "/att.txt --ref-up w");
	EXPECT_EQ(bad.code, 2) << bad.out;
	EXPECT_NE(bad.out.find("'w' is not an axis"), std::string::npos) << bad.out;
	const auto none =
	    run(kBin + "/bims-eval attitude " + d + "/none.txt " + d + "/att.txt");
	EXPECT_NE(none.code, 0);
	EXPECT_NE(none.out.find("none.txt: file not found"), std::string::npos)
	    << none.out;
}
