// bims-run's report.md (bims/apps/run_report.h): the run's figures from
// metrics.json, the scores against the ground truth beside the input, the
// links to its outputs.
#include <bims/apps/run_command.h>
#include <bims/apps/run_report.h>
#include <bims/io/trajectory.h>
#include <bims_test/sample.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

namespace fs = std::filesystem;

namespace
{
std::string readText(const std::string& path)
{
	std::ifstream f(path);
	std::stringstream s;
	s << f.rdbuf();
	return s.str();
}
}  // namespace

TEST(RunReport, FiguresScoresAndLinksOfAHandMadeRun)
{
	const auto d = bims::test::freshTmpDir("bims_test_apps", "run_report");
	const std::string out = d + "/out";
	fs::create_directories(out + "/masks");
	fs::create_directories(d + "/in_gt/masks");
	std::ofstream(d + "/in.rawlog") << "x";
	std::ofstream(out + "/metrics.json") << R"({
  "status": "done", "variant": "fused", "frames_processed": 2,
  "frames_not_measured": 0, "frames_flagged_by": {"anchored": 2},
  "notes": ["no IMU in the input: mode vision"], "scans_read": 2,
  "imu_read": 0, "imu_rejected": 0, "wall_seconds": 0.5, "cpu_seconds": 0.9,
  "peak_resident_mib": 80.0, "fps": 4.0, "data_seconds": 0.1,
  "mean_moving_pixel_fraction": 0.25,
  "stage_ms": {"egomotion": {"median": 3.5, "p95": 4.25, "mean": 3.6, "n": 2},
               "total": {"median": 12.0, "p95": 14.0, "mean": 12.5, "n": 2}},
  "error": ""})";
	// trajectory: 4 poses, the estimate 1 cm off in x at one of them
	bims::Trajectory gt, est;
	for (int k = 0; k < 4; k++)
	{
		gt.push_back({0.1 * k, mrpt::poses::CPose3D(0.1 * k, 0, 0, 0, 0, 0)});
		est.push_back({0.1 * k, mrpt::poses::CPose3D(0.1 * k, 0, 0, 0, 0, 0)});
	}
	bims::saveTumTrajectory(d + "/in_gt/groundtruth.txt", gt);
	bims::saveTumTrajectory(out + "/trajectory.txt", est);
	// masks: label cols 0-1 moving, prediction cols 0 and 2: TP 2 FP 2 FN 2
	cv::Mat l(2, 4, CV_8UC1, cv::Scalar(0)), p = l.clone();
	l.colRange(0, 2) = 255;
	p.col(0) = 255;
	p.col(2) = 255;
	for (const char* n : {"000000.png", "000001.png"})
	{
		cv::imwrite(d + "/in_gt/masks/" + n, l);
		cv::imwrite(out + "/masks/" + n, p);
	}
	bims::apps::writeRunReport(
	    {out, {d + "/in.rawlog"}, "default.ini", "vision", {}});
	const std::string r = readText(out + "/report.md");
	for (const std::string s :
	     {"# bims-run report", "status: **done**", "variant: fused",
	      "`default.ini`", "[effective.ini](effective.ini)",
	      "2 frames of 2 3D scans read", "anchored 2;",
	      "mean moving-pixel fraction 25.00 %", "odometry mode: vision",
	      "0 IMU samples read", "note: no IMU in the input: mode vision",
	      "4.0 frames/s end to end", "| egomotion | 3.50 | 4.25 |",
	      "ATE RMSE 0.0000 m over 4 poses",
	      "precision 0.5000 recall 0.5000 F1 0.5000 IoU 0.3333",
	      "static called moving 0.5000", "[trajectory.txt](trajectory.txt)",
	      "![mask 000001.png](masks/000001.png)",
	      "[metrics.json](metrics.json)"})
		EXPECT_NE(r.find(s), std::string::npos) << s << "\n" << r;
	// without ground truth: says how to score
	fs::remove_all(d + "/in_gt");
	const std::string r2 = bims::apps::runReport(
	    {out, {d + "/in.rawlog"}, "default.ini", "imu", {}});
	EXPECT_NE(r2.find("No ground truth beside the input"), std::string::npos)
	    << r2;
	// no metrics.json: an error naming it
	fs::remove(out + "/metrics.json");
	EXPECT_THROW(bims::apps::runReport({out, {}, "", "", {}}),
	             std::runtime_error);
}

TEST(RunReport, BimsRunWritesItBesideItsOutputs)
{
	const auto d = bims::test::freshTmpDir("bims_test_apps", "run_report_run");
	bims::apps::RunCommand c;
	c.config = bims::test::kDefaultConfig;
	c.rawlogs = {bims::test::kSample};
	c.outDir = d + "/out";
	c.frames = "0:40";
	c.progress = false;
	ASSERT_EQ(bims::apps::runFromCommandLine(c), 0);
	const std::string r = readText(d + "/out/report.md");
	EXPECT_NE(r.find("41 frames of"), std::string::npos) << r;
	EXPECT_NE(r.find("odometry mode: imu"), std::string::npos) << r;
	// the sample's ground truth beside it: the trajectory is scored
	EXPECT_NE(r.find("trajectory against `" + bims::test::kSampleGt),
	          std::string::npos)
	    << r;
	EXPECT_NE(r.find("ATE RMSE"), std::string::npos) << r;
}
