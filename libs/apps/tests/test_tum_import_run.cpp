// bims-import-tum's run (tum_import_run.h) called directly: the report,
// the option checks and the synthetic IMU asked of the program's hook.
#include <bims/apps/app.h>
#include <bims/apps/tum_import_run.h>
#include <bims/common/config.h>
#include <bims/eval/pose_utils.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <mrpt/obs/CObservationIMU.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

namespace
{
namespace fs = std::filesystem;

/** A TUM folder of two 640x480 frames at t = 1.0 and 1.1, with a
 * groundtruth.txt of 6 poses over [0.9, 1.4] when \a withGt. */
std::string tumFolder(const std::string& name, bool withGt)
{
	const auto d = bims::test::freshTmpDir("bims_test_import_run", name);
	fs::create_directories(d + "/rgb");
	fs::create_directories(d + "/depth");
	for (const char* f : {"a", "b"})
	{
		cv::imwrite(d + "/rgb/" + f + ".png",
		            cv::Mat(480, 640, CV_8UC3, cv::Scalar(9, 9, 9)));
		cv::imwrite(d + "/depth/" + f + ".png",
		            cv::Mat(480, 640, CV_16UC1, cv::Scalar(5000)));
	}
	std::ofstream(d + "/rgb.txt") << "1.0 rgb/a.png\n1.1 rgb/b.png\n";
	std::ofstream(d + "/depth.txt") << "1.0 depth/a.png\n1.1 depth/b.png\n";
	if (withGt)
	{
		std::ofstream gt(d + "/groundtruth.txt");
		for (int i = 0; i < 6; i++)
			gt << 0.9 + 0.1 * i << " " << 0.01 * i << " 0 0 0 0 0 1\n";
	}
	return d;
}

/** The message of the exception of type E that runImport(o) throws. */
template <class E>
std::string errorOf(const bims::apps::ImportRunOptions& o)
{
	try
	{
		bims::apps::runImport(o);
	}
	catch (const E& e)
	{
		return e.what();
	}
	return "";
}
}  // namespace

TEST(ImportRun, TheReportNamesFramesImuAndGroundTruth)
{
	bims::eval::ImportSummary s;
	bims::eval::ImportParams p;
	s.frames = 3;
	s.gtDir = "x_gt";
	EXPECT_EQ(bims::apps::importReport("x.rawlog", s, false, false, p),
	          "x.rawlog: 3 RGB-D frames, 0 IMU observations\n"
	          "x_gt: no groundtruth.txt in the folder\n");
	s.imu = 7;
	s.imuLabel = "IMU_SYNTH";
	s.accel = 5;
	s.gtPoses = 2;
	s.framesWithoutGt = 1;
	EXPECT_EQ(bims::apps::importReport("x.rawlog", s, true, true, p),
	          "x.rawlog: 3 RGB-D frames, 7 IMU observations (synthetic, label "
	          "'IMU_SYNTH'), 5 accelerometer samples of accelerometer.txt "
	          "(label 'ACCEL', accelerometer only)\n"
	          "x_gt/groundtruth.txt: 2 poses (T_WC at the frames' stamps, "
	          "Bonn-converted), 1 frames outside the ground truth\n");
}

TEST(ImportRun, BadOptionsAreErrorsBeforeAnyOutput)
{
	const auto d = tumFolder("bad", false);
	bims::apps::ImportRunOptions o;
	o.folder = d;
	o.out = d + "/x.rawlog";
	o.progress = false;
	o.gz = 10;
	EXPECT_EQ(errorOf<bims::UsageError>(o), "--gz must be in 0..9");
	o.gz = 0;
	o.config = d + "/none.ini";
	EXPECT_EQ(errorOf<std::runtime_error>(o),
	          d + "/none.ini: config file not found");
	o.config.reset();
	o.synth_imu = true;  // with the simulator's synthesis (the default)
	EXPECT_EQ(errorOf<std::runtime_error>(o),
	          d + ": --synth-imu needs groundtruth.txt to synthesise from");
	EXPECT_FALSE(fs::exists(o.out));
}

// Issue 39: the guarded image reader's limits are [input] keys of the
// importer's -c CONFIG.ini: a folder's image beyond them is refused naming
// the file, the size and the keys, before it is decoded.
TEST(ImportRun, TheImageLimitsOfTheConfigApplyToTheFoldersImages)
{
	const auto d = tumFolder("limits", false);
	bims::apps::ImportRunOptions o;
	o.folder = d;
	o.out = d + "/x.rawlog";
	o.progress = false;
	o.config = d + "/small.ini";
	std::ofstream(*o.config) << "[input]\nimage_max_side = 600\n";
	const std::string e = errorOf<std::runtime_error>(o);
	EXPECT_NE(e.find(d + "/depth/a.png: cannot read depth image: declares "
	                     "640 x 480 pixels in its PNG header, beyond the 600 "
	                     "per side"),
	          std::string::npos)
	    << e;
	EXPECT_NE(e.find("[input] image_max_side, image_max_pixels"),
	          std::string::npos)
	    << e;
	EXPECT_FALSE(fs::exists(o.out));
	std::ofstream(*o.config) << "[input]\nimage_max_pixels = 307199\n";
	EXPECT_NE(errorOf<std::runtime_error>(o).find("beyond the 16384 per side "
	                                              "and 307199 pixels"),
	          std::string::npos);
	// out of range: an error naming the file, section and key
	std::ofstream(*o.config) << "[input]\nimage_max_side = 0\n";
	EXPECT_NE(errorOf<std::runtime_error>(o).find("[input] image_max_side"),
	          std::string::npos);
	// within them (the defaults: today's), the import runs
	std::ofstream(*o.config) << "[input]\nimage_max_pixels = 307200\n";
	EXPECT_EQ(errorOf<std::exception>(o), "");
	EXPECT_TRUE(fs::exists(o.out));
}

// Issue 55, item 6: [camera] intrinsics that cannot be the images' camera
// (a principal point outside them, a field of view of no camera) are
// refused before any output, saying what is accepted.
TEST(ImportRun, IntrinsicsThatCannotBeTheImagesCameraAreRefused)
{
	const auto d = tumFolder("intrinsics", false);
	bims::apps::ImportRunOptions o;
	o.folder = d;
	o.out = d + "/x.rawlog";
	o.progress = false;
	o.config = d + "/camera.ini";
	std::ofstream(*o.config) << "[camera]\nfx = 525\nfy = 525\ncx = -129\n"
	                            "cy = 239.5\nwidth = 640\nheight = 480\n";
	std::string e = errorOf<std::runtime_error>(o);
	EXPECT_NE(e.find("[camera] of the import: the principal point (cx -129, "
	                 "cy 239.5) is outside the 640x480 image (accepted: 0 <= "
	                 "cx <= 640"),
	          std::string::npos)
	    << e;
	EXPECT_FALSE(fs::exists(o.out));
	std::ofstream(*o.config) << "[camera]\nfx = 90000\nfy = 525\ncx = 319.5\n"
	                            "cy = 239.5\nwidth = 640\nheight = 480\n";
	e = errorOf<std::runtime_error>(o);
	EXPECT_NE(e.find("fx 90000 gives a field of view of 0.407 deg"),
	          std::string::npos)
	    << e;
	EXPECT_FALSE(fs::exists(o.out));
}

TEST(ImportRun, SynthImuTakesTheConvertedTruthLabelCalibrationAndSeed)
{
	const auto d = tumFolder("synth", true);
	std::ofstream(d + "/c.ini") << "[sensors]\nimu_label = XS\n";
	bims::apps::ImportRunOptions o;
	o.folder = d;
	o.out = d + "/x.rawlog";
	o.config = d + "/c.ini";
	o.bonn_gt = true;
	o.synth_imu = true;
	o.seed = 42;
	o.progress = false;
	bims::Trajectory given;
	std::string label;
	bool withCalibration = false;
	uint64_t seed = 0;
	o.synthesize = [&](const bims::Trajectory& gt, const std::string& l,
	                   const mrpt::config::CConfigFileBase* c, uint64_t s)
	{
		given = gt;
		label = l;
		withCalibration = c != nullptr;
		seed = s;
		auto imu = mrpt::obs::CObservationIMU::Create();
		imu->sensorLabel = l + "_SYNTH";
		imu->timestamp = mrpt::Clock::fromDouble(1.05);
		return std::vector<mrpt::obs::CObservation::Ptr>{imu};
	};
	EXPECT_EQ(bims::apps::runImport(o), 0);
	ASSERT_EQ(given.size(), 6u);
	const auto raw = bims::loadTumTrajectory(d + "/groundtruth.txt");
	EXPECT_TRUE(given[2].T_WC.asTPose() ==
	            bims::eval::bonnMarkerToCamera(raw[2].T_WC).asTPose());
	EXPECT_EQ(label, "XS");
	EXPECT_TRUE(withCalibration);
	EXPECT_EQ(seed, 42u);
	size_t imu = 0, n = 0;
	bims::RawlogReader r(o.out);
	while (auto obs = r.next())
	{
		n++;
		imu += obs->sensorLabel == "XS_SYNTH";
	}
	EXPECT_EQ(n, 3u);
	EXPECT_EQ(imu, 1u);
}

// accelerometer.txt is a real sensor of its own: its samples get [import]
// accel_label (accelerometer only), never the synthetic IMU's label, even
// when the config's imu_label names the synthetic one (config/bonn.ini).
TEST(ImportRun, AccelerometerTxtIsARealSensorWithItsOwnLabel)
{
	const auto d = tumFolder("accel", false);
	std::ofstream(d + "/accelerometer.txt")
	    << "# accelerometer data\n1.02 0.1 -9.8 0.2\n1.05 0.0 -9.7 0.1\n";
	std::ofstream(d + "/c.ini") << "[sensors]\nimu_label = IMU_SYNTH\n";
	bims::apps::ImportRunOptions o;
	o.folder = d;
	o.out = d + "/x.rawlog";
	o.config = d + "/c.ini";
	o.progress = false;
	ASSERT_EQ(bims::apps::runImport(o), 0);
	std::vector<std::string> labels;
	std::vector<double> ay;
	bims::RawlogReader r(o.out);
	while (auto obs = r.next())
		if (auto imu =
		        std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(obs))
		{
			labels.push_back(imu->sensorLabel);
			ay.push_back(imu->get(mrpt::obs::IMU_Y_ACC));
			EXPECT_FALSE(imu->has(mrpt::obs::IMU_WX)) << "no gyro invented";
		}
	EXPECT_EQ(labels, (std::vector<std::string>{"ACCEL", "ACCEL"}));
	EXPECT_EQ(ay, (std::vector<double>{-9.8, -9.7}));
	// Another label by [import] accel_label; a synthetic-looking one refused.
	std::ofstream(d + "/c.ini") << "[import]\naccel_label = PHONE_ACC\n";
	o.out = d + "/y.rawlog";
	ASSERT_EQ(bims::apps::runImport(o), 0);
	bims::RawlogReader r2(o.out);
	size_t phone = 0;
	while (auto obs = r2.next()) phone += obs->sensorLabel == "PHONE_ACC";
	EXPECT_EQ(phone, 2u);
	std::ofstream(d + "/c.ini") << "[import]\naccel_label = ACC_SYNTH\n";
	o.out = d + "/z.rawlog";
	const std::string e = errorOf<bims::ConfigError>(o);
	EXPECT_NE(e.find("accel_label"), std::string::npos) << e;
	EXPECT_NE(e.find("SYNTH"), std::string::npos) << e;
	EXPECT_FALSE(fs::exists(o.out));
}
