// bims-odom's run (odometry_run.h): its configuration from the options, the
// tracker's accuracy against the truth, the CSV and the whole run on the
// bundled sample.
#include <bims/apps/app.h>
#include <bims/apps/odometry_run.h>
#include <bims/common/config.h>
#include <bims/eval/trajectory_metrics.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/sim/simulator.h>
#include <bims_test/sample.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/poses/CPose3D.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>

using namespace bims::apps;

namespace
{
using bims::test::kDefaultConfig;
using bims::test::kSample;
using bims::test::kSampleGt;
using bims::test::kSourceDir;

std::vector<std::string> lines(const std::string& path)
{
	std::ifstream f(path);
	std::vector<std::string> v;
	for (std::string l; std::getline(f, l);) v.push_back(l);
	return v;
}

size_t fields(const std::string& line)
{
	return static_cast<size_t>(std::count(line.begin(), line.end(), ',')) + 1;
}
}  // namespace

TEST(OdometryRun, OptionsOverrideTheConfigAndBadValuesAreUsageErrors)
{
	OdometryRunOptions o;
	o.config = kDefaultConfig;
	const auto base = odometryConfig(o);
	EXPECT_EQ(base.odometry.mode, bims::ego::OdometryMode::Imu);
	EXPECT_TRUE(base.odometry.gyro_aid);
	o.mode = "vision";
	o.gyro_aid = "false";
	const auto ec = odometryConfig(o);
	EXPECT_EQ(ec.odometry.mode, bims::ego::OdometryMode::Vision);
	EXPECT_FALSE(ec.odometry.gyro_aid);

	auto bad = o;
	bad.gyro_aid = "maybe";
	EXPECT_THROW(odometryConfig(bad), bims::UsageError);
	bad = o;
	bad.mode = "";  // given, empty: not a mode
	EXPECT_THROW(odometryConfig(bad), bims::UsageError);
	bad = o;
	bad.calib = kSampleGt + "no_such_calibration.ini";
	try
	{
		odometryConfig(bad);
		ADD_FAILURE() << "no error for a missing --calib";
	}
	catch (const bims::UsageError& e)
	{
		EXPECT_EQ(std::string(e.what()),
		          bad.calib + ": no such calibration file");
	}
}

TEST(OdometryRun, AMissingConfigIsAUsageErrorNamingIt)
{
	// the library's error is a ConfigFileMissing; the programs' a usage
	// error (exit code 2), with the same message
	const std::string none = kSampleGt + "no_such_config.ini";
	bims::ego::EgoConfig ec;
	EXPECT_THROW(ec.loadFromFile(none), bims::ConfigFileMissing);
	try
	{
		egoConfigOption(none);
		ADD_FAILURE() << "no error for a missing config";
	}
	catch (const bims::UsageError& e)
	{
		EXPECT_EQ(std::string(e.what()), none + ": no such config file");
	}
}

TEST(OdometryRun, ImuModeWithoutRicIsAConfigErrorNamingTheFile)
{
	const std::string d = bims::test::freshTmpDir("bims_test_source", "odom");
	const std::string ini = d + "/no_ric.ini";
	std::ofstream(ini) << "[odometry]\nmode = imu\n";
	OdometryRunOptions o;
	o.config = ini;
	try
	{
		odometryConfig(o);
		ADD_FAILURE() << "no error without R_IC";
	}
	catch (const bims::ConfigError& e)
	{
		EXPECT_EQ(std::string(e.what()).rfind(ini + ": [calibration] R_IC", 0),
		          0u)
		    << e.what();
	}
	o.mode = "vision";  // vision needs no R_IC
	EXPECT_NO_THROW(odometryConfig(o));
}

TEST(OdometryRun, TrackerAgainstTruthCountsTracksWithinTwoPixels)
{
	// A wall 2 m ahead, the camera moves 0.1 m to the right: a feature
	// moves 50 * 0.1 / 2 = 2.5 px to the left.
	const cv::Mat depth(48, 64, CV_32FC1, cv::Scalar(2.0f));
	Eigen::Matrix3d K;
	K << 50, 0, 32, 0, 50, 24, 0, 0, 1;
	bims::ego::FrameEgomotion r;
	r.attempted = {{20, 20}, {30, 20}, {-10, -10}};  // the last: no depth
	bims::ego::Track good, off;
	good.prev = {20, 20};
	good.cur = {17.6f, 20.3f};
	off.prev = {30, 20};
	off.cur = {29.0f, 20.0f};  // 1.5 px from the truth (27.5, 20): good too
	bims::ego::Track far = off;
	far.cur = {30.0f, 20.0f};  // 2.5 px from the truth
	r.tracks = {good, off, far};
	const mrpt::poses::CPose3D T(0.1, 0, 0, 0, 0, 0);
	const auto t = trackerAgainstTruth(r, depth, K, T, 0.5);
	EXPECT_EQ(t.attempted_with_depth, 2);
	EXPECT_EQ(t.tracked_within_2px, 2);
	EXPECT_NEAR(t.rate_deg_s, 0, 1e-9);
	// 10 degrees of yaw in 0.5 s
	const mrpt::poses::CPose3D R(0, 0, 0, 0, 10 * M_PI / 180, 0);
	EXPECT_NEAR(trackerAgainstTruth(r, depth, K, R, 0.5).rate_deg_s, 20, 1e-9);
}

TEST(OdometryRun, CsvLineHasOneFieldPerHeaderColumn)
{
	bims::ego::FrameEgomotion r;
	r.t = 12.5;
	const std::string line = odometryCsvLine(r, {});
	EXPECT_EQ(fields(line), fields(odometryCsvHeader()));
	EXPECT_EQ(line.rfind("12.500000,", 0), 0u) << line;
	EXPECT_NE(line.find(",nan,0,0,"), std::string::npos) << line;
	// the anchor's note (none), then the inertial filter's columns (it did
	// not run: no degeneracy analysed)
	EXPECT_NE(line.find(",-,-1,0.000,"), std::string::npos) << line;
	EXPECT_EQ(line.back(), '\n');
	r.anchor.why = "no keyframe";
	EXPECT_EQ(odometryCsvLine(r, {1.5, 7, 3}).find(",1.500,7,3,") !=
	              std::string::npos,
	          true);
}

TEST(OdometryRun, RunsTheSampleIntoATrajectoryCsvAndSummary)
{
	const std::string d = bims::test::freshTmpDir("bims_test_source", "run");
	OdometryRunOptions o;
	o.config = kDefaultConfig;
	o.rawlog = kSample;
	o.out = d + "/traj.txt";
	o.csv = d + "/frames.csv";
	o.gt = kSampleGt + "groundtruth.txt";
	o.masks = kSampleGt + "masks";
	o.max_frames = 12;
	o.progress = false;
	testing::internal::CaptureStderr();
	EXPECT_EQ(runOdometry(o), 0);
	const std::string err = testing::internal::GetCapturedStderr();
	// first which IMU it uses (issue 35), then the summary
	EXPECT_EQ(err.rfind("bims-odom: " + kSample +
	                        ": using the IMU labelled 'IMU' (gyro + accel + "
	                        "mag)\nbims-odom: 12 frames (0 with the motion not "
	                        "measured), ",
	                    0),
	          0u)
	    << err;
	EXPECT_NE(err.find("bims-odom: masks of " + *o.masks +
	                   " for 11 of 12 "
	                   "frames\n"),
	          std::string::npos)
	    << err;
	EXPECT_EQ(bims::loadTumTrajectory(o.out).size(), 12u);
	const auto csv = lines(*o.csv);
	ASSERT_EQ(csv.size(), 13u);
	EXPECT_EQ(csv[0] + "\n", odometryCsvHeader());
	int within2px = 0;
	for (size_t i = 2; i < csv.size(); i++)
	{
		std::istringstream s(csv[i]);
		std::string f;
		for (int k = 0; k <= 12; k++) std::getline(s, f, ',');
		within2px += std::stoi(f);
	}
	EXPECT_GT(within2px, 100);  // the tracker follows the truth

	auto same = o;  // an output that is an input: refused before any work
	same.csv = kSample;
	EXPECT_THROW(runOdometry(same), bims::UsageError);
	auto noMasks = o;
	noMasks.masks = d + "/none";
	EXPECT_THROW(runOdometry(noMasks), std::runtime_error);
}

// Issue 39: an output folder that is not there was found after the whole
// run; a rawlog cut short gave no trajectory at all.
TEST(OdometryRun,
     AnUnwritableOutputIsSaidBeforeTheRunAndACutRawlogKeepsItsPoses)
{
	const std::string d = bims::test::freshTmpDir("bims_test_source", "cut");
	OdometryRunOptions o;
	o.config = kDefaultConfig;
	o.rawlog = kSample;
	o.out = d + "/no/such/folder/traj.txt";
	o.progress = false;
	try
	{
		runOdometry(o);
		FAIL();
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("does not exist"),
		          std::string::npos)
		    << e.what();
	}

	// the sample cut to 40 % of its bytes
	const std::string cut = d + "/cut.rawlog";
	{
		std::ifstream in(kSample, std::ios::binary);
		std::string bytes((std::istreambuf_iterator<char>(in)),
		                  std::istreambuf_iterator<char>());
		std::ofstream(cut, std::ios::binary)
		    .write(bytes.data(),
		           static_cast<std::streamsize>(bytes.size() * 4 / 10));
	}
	o.rawlog = cut;
	o.out = d + "/traj.txt";
	std::string what;
	testing::internal::CaptureStderr();
	try
	{
		runOdometry(o);
	}
	catch (const std::runtime_error& e)
	{
		what = e.what();
	}
	testing::internal::GetCapturedStderr();
	EXPECT_NE(what.find("cut.rawlog"), std::string::npos) << what;
	EXPECT_NE(what.find("frames before it are in " + o.out), std::string::npos)
	    << what;
	const auto poses = bims::loadTumTrajectory(o.out).size();
	EXPECT_GT(poses, 20u);
	EXPECT_LT(poses, 150u);
	EXPECT_NE(what.find(std::to_string(poses) + " frames"), std::string::npos)
	    << what;
}

TEST(DepthInertial, OnABlankWallTheImuCarriesWhatTheDepthCannotSee)
{
	// The simulator's blank wall, depth only + IMU, 3 s: a sideways walk
	// along one flat wall, which no depth alignment can see. With the
	// inertial filter (the alignment's information measured on the geometry:
	// the wall's in-plane directions have none) the accelerometer carries
	// them; without it the translation slips along the wall.
	const std::string d =
	    bims::test::freshTmpDir("bims_test_source", "blank_wall");
	bims::sim::SimConfig c =
	    bims::sim::SimConfig::load(kSourceDir + "/config/sim/blank_wall.ini");
	c.rgb.enabled = false;
	c.seq.frames = 90;
	c.camera.setResolution("320x240");
	const std::string rawlog = d + "/wall.rawlog";
	bims::sim::runSimulation(c, rawlog, 1);
	const std::string gt = d + "/wall_gt/";
	double ate[2] = {0, 0};
	for (int on = 0; on < 2; on++)
	{
		// config/default.ini with the filter on or off
		std::ifstream in(kDefaultConfig);
		std::string ini{std::istreambuf_iterator<char>(in), {}};
		const size_t k = ini.find("[inertial]");
		ASSERT_NE(k, std::string::npos);
		if (on) ini.replace(ini.find("enable=false", k), 12, "enable=true");
		const std::string cfg = d + "/c" + std::to_string(on) + ".ini";
		std::ofstream(cfg) << ini;
		OdometryRunOptions o;
		o.config = cfg;
		o.rawlog = rawlog;
		o.calib = gt + "calibration.ini";
		o.out = d + "/traj" + std::to_string(on) + ".txt";
		o.progress = false;
		if (on) o.gravity_attitude = d + "/levelled.txt";
		ASSERT_EQ(runOdometry(o), 0);
		ate[on] = bims::eval::computeAte(
		              bims::loadTumTrajectory(gt + "groundtruth.txt"),
		              bims::loadTumTrajectory(o.out))
		              .stats.rmse;
	}
	std::printf(
	    "blank wall, depth + IMU: ATE %.4f m with the inertial "
	    "filter, %.4f m without\n",
	    ate[1], ate[0]);
	EXPECT_LT(ate[1], 0.02);  // measured 0.004
	EXPECT_GT(ate[0], 0.10);  // measured 0.165
	// the attitude levelled by the filter's gravity: the camera's up
	// direction against the truth's (both worlds z up)
	const auto truth = bims::loadTumTrajectory(gt + "groundtruth.txt");
	const auto levelled = bims::loadTumTrajectory(d + "/levelled.txt");
	ASSERT_EQ(levelled.size(), truth.size() - 1);  // the first frame: none
	double sum2 = 0;
	for (size_t i = 0; i < levelled.size(); i++)
	{
		const auto up = [](const mrpt::poses::CPose3D& T)
		{
			const auto& R = T.getRotationMatrix();
			return Eigen::Vector3d(R(2, 0), R(2, 1), R(2, 2));  // R^T z
		};
		const double a = std::acos(std::clamp(
		    up(levelled[i].T_WC).dot(up(truth[i + 1].T_WC)), -1.0, 1.0));
		sum2 += a * a;
	}
	const double tiltDeg = std::sqrt(sum2 / levelled.size()) * 180 / M_PI;
	std::printf("levelled attitude: tilt %.3f deg RMS\n", tiltDeg);
	EXPECT_LT(tiltDeg, 1.0);
}

namespace
{
/** The bundled sample rewritten to \a out with each IMU observation passed
 * through \a edit (its time [s] from the first one; false: left out). */
void rewriteImu(
    const std::string& out,
    const std::function<bool(mrpt::obs::CObservationIMU&, double)>& edit)
{
	bims::RawlogReader in(kSample);
	bims::RawlogWriter w(out, 1);
	double t0 = -1;
	while (auto o = in.next())
	{
		if (auto* imu = dynamic_cast<mrpt::obs::CObservationIMU*>(o.get()))
		{
			const double t = mrpt::Clock::toDouble(imu->timestamp);
			if (t0 < 0) t0 = t;
			if (!edit(*imu, t - t0)) continue;
		}
		w.write(*o);
	}
}
}  // namespace

TEST(DepthInertial, ImuGapsSaturationAndAStoppedImuAreFlaggedWithoutAJump)
{
	// The bundled sample with the inertial filter on and its IMU broken in
	// four ways (a 0.5 s gap, stopped after 3 s, stamped on another clock,
	// an accelerometer saturated for 0.1 s): each is flagged on the frames it
	// touches, and the motion prior carries them without a jump (largest
	// 1-frame translation error against the ground truth below 3 cm).
	const std::string d =
	    bims::test::freshTmpDir("bims_test_source", "bad_imu");
	std::ifstream in(kDefaultConfig);
	std::string ini{std::istreambuf_iterator<char>(in), {}};
	const size_t k = ini.find("enable=false", ini.find("[inertial]"));
	ASSERT_NE(k, std::string::npos);
	ini.replace(k, 12, "enable=true");
	const std::string cfg = d + "/inertial.ini";
	std::ofstream(cfg) << ini;
	struct Case
	{
		const char* name;
		std::function<bool(mrpt::obs::CObservationIMU&, double)> edit;
		const char* flag;
	};
	const std::vector<Case> cases = {
	    {"gap", [](auto&, double t) { return t < 1.5 || t >= 2.0; },
	     "inertial_prior"},
	    {"stopped", [](auto&, double t) { return t < 3.0; }, "inertial_prior"},
	    {"other clock",
	     [](mrpt::obs::CObservationIMU& o, double)
	     {
		     o.timestamp += std::chrono::seconds(1000);
		     return true;
	     },
	     "inertial_prior"},
	    {"saturated",
	     [](mrpt::obs::CObservationIMU& o, double t)
	     {
		     if (t >= 1.5 && t < 1.6) o.set(mrpt::obs::IMU_X_ACC, 90.0);
		     return true;
	     },
	     "accel_saturated"}};
	for (const Case& c : cases)
	{
		SCOPED_TRACE(c.name);
		std::string name = c.name;
		std::replace(name.begin(), name.end(), ' ', '_');
		const std::string rawlog = d + "/" + name + ".rawlog";
		rewriteImu(rawlog, c.edit);
		OdometryRunOptions o;
		o.config = cfg;
		o.rawlog = rawlog;
		o.calib = kSampleGt + "calibration.ini";
		o.out = d + "/" + name + ".txt";
		o.csv = d + "/" + name + ".csv";
		o.progress = false;
		ASSERT_EQ(runOdometry(o), 0);
		std::ifstream csv(*o.csv);
		int flagged = 0;
		for (std::string line; std::getline(csv, line);)
			flagged += line.find(c.flag) != std::string::npos;
		EXPECT_GT(flagged, 0);
		const auto gt = bims::loadTumTrajectory(kSampleGt + "groundtruth.txt");
		const auto est = bims::loadTumTrajectory(o.out);
		const auto ate = bims::eval::computeAte(gt, est);
		const auto jumps = bims::eval::computeJumps(gt, est, ate.pairs);
		std::printf(
		    "%s: %d frames flagged %s, ATE %.4f m, largest 1-frame "
		    "error %.4f m\n",
		    c.name, flagged, c.flag, ate.stats.rmse, jumps.stats.max);
		EXPECT_LT(jumps.stats.max, 0.03);
		EXPECT_LT(ate.stats.rmse, 0.05);
	}
}
