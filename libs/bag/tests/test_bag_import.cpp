// bims-import-bag against bags the tests write themselves with the rosbag
// API, from the bundled sample's simulated frames and IMU: every pixel,
// stamp and axis checked against the sample; the accelerometer and gyro of
// RealSense's two topics merged; a TUM-layout bag equal, byte for byte, to
// the TUM folder of the same frames; and the bad bags users meet.
#include <bims/bag/bag_import.h>
#include <bims/bag/compressed_image.h>
#include <bims/common/config.h>
#include <bims/ego/attitude_filter.h>
#include <bims/eval/tum_import.h>
#include <bims/io/rawlog.h>
#include <bims_test/bag_writer.h>
#include <bims_test/error_of.h>
#include <bims_test/observations.h>
#include <bims_test/run_command.h>
#include <bims_test/sample.h>
#include <bims_test/text.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <mrpt/core/format.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

namespace
{
namespace fs = std::filesystem;
using namespace bims;
using namespace bims::test;
using mrpt::obs::CObservation3DRangeScan;
using mrpt::obs::CObservationIMU;

const std::string kImport = std::string(BIMS_BIN_DIR) + "/bims-import-bag";
const std::string kRun = std::string(BIMS_BIN_DIR) + "/bims-run";

/** The sample's first 24 frames and their IMU samples. */
const test::Observations& sample()
{
	return test::sampleObservations();
}

using Imported = test::Observations;

Imported readRawlog(const std::string& path)
{
	return test::readObservations(path);
}

bag::BagImportSummary import(const std::string& bagPath, const std::string& out,
                             bag::BagImportParams p = {})
{
	bag::BagImportOptions o;
	o.gzLevel = 0;
	return bag::importBag({bagPath}, out, p, o);
}

std::string errorOf(const std::function<void()>& f)
{
	return bims::test::errorOf(f, "(no error)");
}

/** Every frame of \a got equals the sample's: range image, colour, stamp
 * (to the microsecond of the bag), camera. */
void expectTheSampleFrames(const Imported& got, size_t n)
{
	const auto& s = sample();
	ASSERT_EQ(got.frames.size(), n);
	for (size_t k = 0; k < n; k++)
	{
		const auto& a = *got.frames[k];
		const auto& b = *s.frames[k];
		EXPECT_NEAR(secondsOf(a.timestamp), secondsOf(b.timestamp), 1.1e-6);
		EXPECT_EQ(a.sensorLabel, "RGBD");
		EXPECT_TRUE(a.range_is_depth);
		ASSERT_EQ(a.rangeImage.rows(), b.rangeImage.rows());
		ASSERT_EQ(a.rangeImage.cols(), b.rangeImage.cols());
		EXPECT_FLOAT_EQ(a.rangeUnits, 0.001f);
		EXPECT_TRUE((a.rangeImage.array() == b.rangeImage.array()).all())
		    << "frame " << k;
		EXPECT_DOUBLE_EQ(a.cameraParams.fx(), b.cameraParams.fx());
		EXPECT_DOUBLE_EQ(a.cameraParams.cy(), b.cameraParams.cy());
		ASSERT_TRUE(a.hasIntensityImage);
		cv::Mat d;
		cv::absdiff(bgrOf(a), bgrOf(b), d);
		EXPECT_EQ(cv::countNonZero(d.reshape(1)), 0) << "frame " << k;
	}
}

TEST(ImportBag, RealSenseLayoutKeepsEveryPixelStampAndAxis)
{
	for (const auto c : {rosbag::compression::Uncompressed,
	                     rosbag::compression::LZ4, rosbag::compression::BZ2})
	{
		SCOPED_TRACE(static_cast<int>(c));
		const auto d = test::freshTmpDir("bims_bag", "realsense");
		BagSpec spec;
		spec.compression = c;
		spec.colour = c == rosbag::compression::LZ4 ? "bgr8" : "rgb8";
		writeBag(d + "/rs.bag", spec, sample().frames, sample().imu);
		const auto sum = import(d + "/rs.bag", d + "/rs.rawlog");
		EXPECT_EQ(sum.layout, bag::BagLayout::RealSense);
		EXPECT_EQ(sum.frames, 24u);
		const auto got = readRawlog(d + "/rs.rawlog");
		expectTheSampleFrames(got, 24);
		// the IMU within the frames' span, every axis as recorded
		const auto& s = sample();
		const double t0 = secondsOf(s.frames.front()->timestamp);
		std::vector<CObservationIMU::Ptr> want;
		for (const auto& m : s.imu)
			if (secondsOf(m->timestamp) >= t0 - 1e-6) want.push_back(m);
		ASSERT_EQ(got.imu.size(), want.size());
		EXPECT_EQ(sum.imuOutside, s.imu.size() - want.size());
		using namespace mrpt::obs;
		for (size_t i = 0; i < want.size(); i++)
		{
			EXPECT_EQ(got.imu[i]->sensorLabel, "IMU");
			EXPECT_NEAR(secondsOf(got.imu[i]->timestamp),
			            secondsOf(want[i]->timestamp), 1.1e-6);
			for (auto k :
			     {IMU_WX, IMU_WY, IMU_WZ, IMU_X_ACC, IMU_Y_ACC, IMU_Z_ACC})
				EXPECT_EQ(got.imu[i]->get(k), want[i]->get(k)) << i;
			EXPECT_FALSE(got.imu[i]->has(IMU_MAG_X));
		}
	}
}

/** R_WI of the attitude filter fed \a imu (label IMU), at \a stamps. */
std::vector<Eigen::Quaterniond> attitudes(
    const std::vector<CObservationIMU::Ptr>& imu,
    const std::vector<double>& stamps)
{
	ego::AttitudeFilter f;
	std::vector<Eigen::Quaterniond> out;
	size_t i = 0;
	for (double t : stamps)
	{
		for (; i < imu.size() && secondsOf(imu[i]->timestamp) <= t; i++)
			f.add(sensors::imuSampleFrom(*imu[i]));
		const auto q = f.attitudeAt(t);
		out.push_back(q ? *q : Eigen::Quaterniond(0, 0, 0, 0));
	}
	return out;
}

TEST(ImportBag, SeparateAccelAndGyroAreMergedIntoWholeSamplesAtTheGyroRate)
{
	const auto d = test::freshTmpDir("bims_bag", "split");
	BagSpec spec;
	spec.splitImu = true;
	spec.mag = true;
	spec.compression = rosbag::compression::LZ4;
	writeBag(d + "/split.bag", spec, sample().frames, sample().imu);
	bag::BagImportParams p;
	p.topics.mag = "/imu/mag";
	const auto sum = import(d + "/split.bag", d + "/split.rawlog", p);
	const auto got = readRawlog(d + "/split.rawlog");
	expectTheSampleFrames(got, 24);
	EXPECT_NE(sum.imuSource.find("merged"), std::string::npos);
	EXPECT_TRUE(sum.imuHasGyro && sum.imuHasAccel && sum.imuHasMag);

	// the gyro's stamps, each sample whole; the IMU written directly
	const auto& s = sample();
	const double t0 = secondsOf(s.frames.front()->timestamp),
	             t1 = secondsOf(s.frames[23]->timestamp);
	std::vector<CObservationIMU::Ptr> direct;
	for (const auto& m : s.imu)
		if (secondsOf(m->timestamp) >= t0 - 1e-6 &&
		    secondsOf(m->timestamp) <= t1 + 1e-6)
			direct.push_back(m);
	using namespace mrpt::obs;
	ASSERT_GE(got.imu.size() + 1, direct.size());  // the last may lack accel
	ASSERT_LE(got.imu.size(), direct.size());
	for (size_t i = 0; i < got.imu.size(); i++)
	{
		const auto& g = *got.imu[i];
		EXPECT_NEAR(secondsOf(g.timestamp), secondsOf(direct[i]->timestamp),
		            1.1e-6);
		for (auto k : {IMU_WX, IMU_WY, IMU_WZ})
			EXPECT_EQ(g.get(k), direct[i]->get(k));
		for (auto k : {IMU_X_ACC, IMU_Y_ACC, IMU_Z_ACC, IMU_MAG_X})
			EXPECT_TRUE(g.has(k));
		EXPECT_NEAR(g.get(IMU_MAG_X), direct[i]->get(IMU_MAG_X), 1e-9);
	}
	// the attitude filter on the merged samples, against the same on the
	// IMU written directly: within 0.1 degrees at every frame
	std::vector<double> stamps;
	for (size_t k = 1; k < 23; k++)
		stamps.push_back(secondsOf(s.frames[k]->timestamp));
	const auto a = attitudes(got.imu, stamps), b = attitudes(direct, stamps);
	double worst = 0;
	for (size_t k = 0; k < stamps.size(); k++)
		worst = std::max(worst, a[k].angularDistance(b[k]) * 180 / M_PI);
	EXPECT_LT(worst, 0.1);
	EXPECT_GT(a.back().norm(), 0.5);  // the filter ran
}

TEST(ImportBag, MergingInterpolatesTheAccelerometerAndCountsWhatItLeavesOut)
{
	std::vector<bag::ImuSample> accel(3), gyro(5);
	for (int i = 0; i < 3; i++)
	{
		accel[i].t = 1.0 + 0.02 * i;
		accel[i].a[0] = 10.0 * i;
	}
	for (int i = 0; i < 5; i++) gyro[i].t = 0.995 + 0.01 * i;
	size_t leftOut = 0;
	const auto m = bag::mergeAccelGyro(accel, gyro, leftOut);
	// 0.995 is before the accelerometer
	ASSERT_EQ(m.size(), 4u);
	EXPECT_EQ(leftOut, 1u);
	EXPECT_NEAR(m[0].a[0], 2.5, 1e-9);   // at 1.005
	EXPECT_NEAR(m[1].a[0], 7.5, 1e-9);   // at 1.015
	EXPECT_NEAR(m[2].a[0], 12.5, 1e-9);  // at 1.025
	EXPECT_NEAR(m[3].a[0], 17.5, 1e-9);  // at 1.035
	gyro.push_back(gyro.back());
	gyro.back().t = 1.045;  // after it
	bag::mergeAccelGyro(accel, gyro, leftOut);
	EXPECT_EQ(leftOut, 2u);
	EXPECT_TRUE(m[0].hasGyro && m[0].hasAccel);
}

TEST(ImportBag, StampsAreTheDecimalsOfTheirSecondsAndNanoseconds)
{
	EXPECT_EQ(bag::stampSeconds(1305031102, 175304000),
	          std::strtod("1305031102.175304", nullptr));
	EXPECT_EQ(bag::stampSeconds(0, 1), 1e-9);
	EXPECT_EQ(bag::stampSeconds(12, 0), 12.0);
}

// Issue 55, item 7: a stamp of nsec >= 1e9 (written without ROS's
// normalisation) was read as the text "sec.nsec" (999 s 1e9 ns as 999.1);
// normalised as ROS does, for the ROS 1 reader (ROS 2: Ros2Import.*).
TEST(ImportBag, NonCanonicalStampsAreNormalisedAsRosDoes)
{
	EXPECT_EQ(bag::stampSeconds(999, 1000000000), 1000.0);
	EXPECT_EQ(bag::stampSeconds(999, 1500000000), 1000.5);
	EXPECT_EQ(bag::stampSeconds(4294967295u, 4294967295u),
	          std::strtod("4294967299.294967295", nullptr));
	// a bag whose headers all carry a second in their nanoseconds
	const auto d = test::freshTmpDir("bims_bag", "nsec");
	const auto shifted = [](std_msgs::Header& h)
	{
		h.stamp.sec -= 1;
		h.stamp.nsec += 1000000000;
	};
	{
		rosbag::Bag b(d + "/nsec.bag", rosbag::bagmode::Write);
		const auto layout = bag::layoutTopics(bag::BagLayout::RealSense);
		for (size_t k = 0; k < 3; k++)
		{
			const auto& f = *sample().frames[k];
			const ros::Time t = rosTime(secondsOf(f.timestamp));
			auto info = infoMsg(f);
			auto depth = depthMsg(f, false);
			auto colour = colourMsg(f, "rgb8");
			shifted(info.header);
			shifted(depth.header);
			shifted(colour.header);
			b.write(layout.cameraInfo, t, info);
			b.write(layout.depth, t, depth);
			b.write(layout.colour, t, colour);
		}
	}
	const auto sum = import(d + "/nsec.bag", d + "/o.rawlog");
	EXPECT_EQ(sum.frames, 3u);
	expectTheSampleFrames(readRawlog(d + "/o.rawlog"), 3);
}

// Issue 55, item 6: a CameraInfo that cannot be the images' camera is
// refused saying what is accepted; a K that changes mid-bag is noted (the
// first is used for every frame).
TEST(ImportBag, IntrinsicsThatCannotBeAreRefusedAndAChangeIsNoted)
{
	const auto d = test::freshTmpDir("bims_bag", "intrinsics");
	const auto layout = bag::layoutTopics(bag::BagLayout::RealSense);
	const auto write =
	    [&](const std::string& path,
	        const std::function<void(sensor_msgs::CameraInfo&, size_t)>& edit)
	{
		rosbag::Bag b(path, rosbag::bagmode::Write);
		for (size_t k = 0; k < 4; k++)
		{
			const auto& f = *sample().frames[k];
			const ros::Time t = rosTime(secondsOf(f.timestamp));
			auto info = infoMsg(f);
			edit(info, k);
			b.write(layout.cameraInfo, t, info);
			b.write(layout.depth, t, depthMsg(f, false));
			b.write(layout.colour, t, colourMsg(f, "rgb8"));
		}
	};
	write(d + "/cx.bag",
	      [](sensor_msgs::CameraInfo& m, size_t) { m.K[2] = -1e6; });
	auto e = errorOf([&] { import(d + "/cx.bag", d + "/o.rawlog"); });
	EXPECT_NE(e.find("topic /camera/color/camera_info: CameraInfo K of a "
	                 "320x240 image: the principal point (cx -1e+06"),
	          std::string::npos)
	    << e;
	EXPECT_NE(e.find("accepted: 0 <= cx <= 320"), std::string::npos) << e;
	EXPECT_FALSE(fs::exists(d + "/o.rawlog"));
	// a K made for 1280x960 on these images
	write(d + "/big.bag",
	      [](sensor_msgs::CameraInfo& m, size_t)
	      {
		      m.K[0] = m.K[4] = 1100;
		      m.K[2] = 640;
		      m.K[5] = 480;
	      });
	e = errorOf([&] { import(d + "/big.bag", d + "/o.rawlog"); });
	EXPECT_NE(e.find("is outside the 320x240 image"), std::string::npos) << e;
	// a focal length of no camera
	write(d + "/fx.bag",
	      [](sensor_msgs::CameraInfo& m, size_t) { m.K[0] = 1e300; });
	e = errorOf([&] { import(d + "/fx.bag", d + "/o.rawlog"); });
	EXPECT_NE(e.find("fx 1e+300 gives a field of view of 0 deg"),
	          std::string::npos)
	    << e;
	// K changes from the third message on
	write(d + "/change.bag",
	      [](sensor_msgs::CameraInfo& m, size_t k)
	      {
		      if (k >= 2) m.K[0] += 10;
	      });
	const auto sum = import(d + "/change.bag", d + "/o.rawlog");
	EXPECT_EQ(sum.frames, 4u);
	EXPECT_EQ(sum.cameraInfoChanges, 2u);
	EXPECT_EQ(sum.camera.fx(), sample().frames[0]->cameraParams.fx());
	bool said = false;
	for (const auto& n : sum.notes)
		said = said || n.find(
		                   "topic /camera/color/camera_info: the "
		                   "CameraInfo changes mid-bag (2 of its 4 "
		                   "messages differ from the first, from message "
		                   "2 on): the first is used for every frame") !=
		                   std::string::npos;
	EXPECT_TRUE(said);
}

// Issue 55, item 1: an output that is a FIFO was replaced by a regular
// file; refused, naming it, and left as it was (the output guard's rule:
// OutputPaths.AFifoOrADeviceAsOutputIsRefusedNeverReplaced). A bag that is
// a FIFO is refused too, not waited on.
TEST(ImportBag, AFifoAsOutputOrAsBagIsRefusedNamingIt)
{
	const auto d = test::freshTmpDir("bims_bag", "fifo");
	if (::mkfifo((d + "/out.rawlog").c_str(), 0600) != 0 ||
	    ::mkfifo((d + "/in.bag").c_str(), 0600) != 0)
		GTEST_SKIP() << "mkfifo refused here: " << std::strerror(errno);
	BagSpec spec;
	spec.frames = 3;
	writeBag(d + "/s.bag", spec, sample().frames, sample().imu);
	auto e = errorOf([&] { import(d + "/s.bag", d + "/out.rawlog"); });
	EXPECT_NE(e.find(d + "/out.rawlog: is a FIFO (named pipe), not a regular "
	                     "file"),
	          std::string::npos)
	    << e;
	EXPECT_TRUE(fs::is_fifo(d + "/out.rawlog"));
	e = errorOf([&] { import(d + "/in.bag", d + "/o.rawlog"); });
	EXPECT_NE(e.find("a FIFO (named pipe), not a regular file"),
	          std::string::npos)
	    << e;
	EXPECT_FALSE(fs::exists(d + "/o.rawlog"));
}

/** The sample as a TUM RGB-D folder: rgb.txt, depth.txt (PNGs, 5000 per
 * metre), accelerometer.txt; stamps with 6 decimals. */
void writeTumFolder(const std::string& dir, size_t n)
{
	fs::create_directories(dir + "/rgb");
	fs::create_directories(dir + "/depth");
	std::ofstream rgb(dir + "/rgb.txt"), depth(dir + "/depth.txt"),
	    acc(dir + "/accelerometer.txt");
	rgb << "# colour images\n# file\n# timestamp filename\n";
	depth << "# depth maps\n# file\n# timestamp filename\n";
	acc << "# accelerometer data\n# file\n# timestamp ax ay az\n";
	const auto& s = sample();
	char t[64];
	size_t i = 0;
	for (size_t k = 0; k < n; k++)
	{
		const auto& f = *s.frames[k];
		const double tf = secondsOf(f.timestamp);
		for (; i < s.imu.size() && secondsOf(s.imu[i]->timestamp) <= tf; i++)
		{
			using namespace mrpt::obs;
			const auto& o = *s.imu[i];
			const ros::Time ti = rosTime(secondsOf(o.timestamp));
			// every digit: the file's values are the bag's
			acc << mrpt::format("%u.%06u %.17g %.17g %.17g\n", ti.sec,
			                    ti.nsec / 1000, o.get(IMU_X_ACC),
			                    o.get(IMU_Y_ACC), o.get(IMU_Z_ACC));
		}
		const ros::Time rt = rosTime(tf);
		std::snprintf(t, sizeof(t), "%u.%06u", rt.sec, rt.nsec / 1000);
		cv::Mat png(f.rangeImage.rows(), f.rangeImage.cols(), CV_16UC1);
		for (int v = 0; v < png.rows; v++)
			for (int u = 0; u < png.cols; u++)
				png.at<uint16_t>(v, u) = tumUnits(f, v, u);
		cv::imwrite(dir + "/depth/" + t + ".png", png);
		cv::imwrite(dir + "/rgb/" + t + ".png", bgrOf(f));
		rgb << t << " rgb/" << t << ".png\n";
		depth << t << " depth/" << t << ".png\n";
	}
}

/** Where two rawlogs first differ: the observation and what in it. */
std::string firstDifference(const std::string& a, const std::string& b)
{
	RawlogReader ra(a), rb(b);
	for (size_t i = 0;; i++)
	{
		const auto oa = ra.next(), ob = rb.next();
		if (!oa || !ob) return oa || ob ? "one ends first" : "none found";
		std::string what;
		if (oa->GetRuntimeClass() != ob->GetRuntimeClass())
			what = "class";
		else if (oa->sensorLabel != ob->sensorLabel)
			what = "label";
		else if (oa->timestamp != ob->timestamp)
			what = mrpt::format("stamp %.9f vs %.9f", secondsOf(oa->timestamp),
			                    secondsOf(ob->timestamp));
		auto ia = std::dynamic_pointer_cast<CObservationIMU>(oa),
		     ib = std::dynamic_pointer_cast<CObservationIMU>(ob);
		if (what.empty() && ia && ib &&
		    ia->rawMeasurements != ib->rawMeasurements)
			what = "IMU values";
		auto fa = std::dynamic_pointer_cast<CObservation3DRangeScan>(oa),
		     fb = std::dynamic_pointer_cast<CObservation3DRangeScan>(ob);
		if (what.empty() && fa && fb)
		{
			if (!(fa->rangeImage.array() == fb->rangeImage.array()).all())
				what = "range image";
			else if (fa->cameraParams.intrinsicParams !=
			         fb->cameraParams.intrinsicParams)
				what = "camera";
		}
		if (!what.empty())
			return "observation " + std::to_string(i) + " (" + oa->sensorLabel +
			       "): " + what;
	}
}

TEST(ImportBag, ATumLayoutBagGivesTheRawlogOfTheTumFolderOfTheSameFrames)
{
	const auto d = test::freshTmpDir("bims_bag", "tum");
	BagSpec spec;
	spec.tum = true;
	spec.compression = rosbag::compression::BZ2;
	spec.frames = 12;
	writeBag(d + "/tum.bag", spec, sample().frames, sample().imu);
	writeTumFolder(d + "/folder", 12);
	const auto& f0 = *sample().frames[0];
	eval::ImportParams tp;
	tp.camera.fx = f0.cameraParams.fx();
	tp.camera.fy = f0.cameraParams.fy();
	tp.camera.cx = f0.cameraParams.cx();
	tp.camera.cy = f0.cameraParams.cy();
	tp.camera.width = static_cast<int>(f0.cameraParams.ncols);
	tp.camera.height = static_cast<int>(f0.cameraParams.nrows);
	eval::ImportOptions to;
	to.gzLevel = 0;
	eval::importTum(d + "/folder", d + "/folder.rawlog", tp, to);

	bag::BagImportParams bp;
	bp.layout = bag::BagLayout::Tum;
	const auto sum = import(d + "/tum.bag", d + "/bag.rawlog", bp);
	EXPECT_EQ(sum.frames, 12u);
	EXPECT_EQ(sum.depthEncoding, "32FC1");
	EXPECT_GT(sum.accelOnly, 0u);
	EXPECT_EQ(sum.accelOnly, sum.imu);
	const std::string a = test::fileText(d + "/folder.rawlog"),
	                  b = test::fileText(d + "/bag.rawlog");
	ASSERT_GT(a.size(), 1000000u);
	EXPECT_TRUE(a == b) << a.size() << " vs " << b.size() << " bytes; "
	                    << firstDifference(d + "/folder.rawlog",
	                                       d + "/bag.rawlog");
	const auto got = readRawlog(d + "/bag.rawlog");
	ASSERT_FALSE(got.imu.empty());
	EXPECT_EQ(got.imu[0]->sensorLabel, "ACCEL");
	EXPECT_FALSE(got.imu[0]->has(mrpt::obs::IMU_WX));
}

TEST(ImportBag, TheProgramImportsBothPresetsAndBimsRunsTheResult)
{
	const auto d = test::freshTmpDir("bims_bag", "app");
	BagSpec rs;
	rs.frames = 12;
	writeBag(d + "/rs.bag", rs, sample().frames, sample().imu);
	auto r = test::runCommand("'" + kImport + "' '" + d + "/rs.bag' --topics");
	EXPECT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("/camera/aligned_depth_to_color/image_raw"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("sensor_msgs/Imu"), std::string::npos) << r.out;

	r = test::runCommand("'" + kImport + "' '" + d + "/rs.bag' -o '" + d +
	                     "/rs.rawlog' -q");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("12 RGB-D frames of 320x240"), std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("IMU samples (gyro, accel) from topic /camera/imu"),
	          std::string::npos)
	    << r.out;
	r = test::runCommand("'" + kRun + "' '" + test::kDefaultConfig + "' '" + d +
	                     "/rs.rawlog' -o '" + d + "/run' -q");
	EXPECT_EQ(r.code, 0) << r.out;
	EXPECT_TRUE(fs::exists(d + "/run/masks/000011.png")) << r.out;

	BagSpec tum;
	tum.tum = true;
	tum.frames = 12;
	writeBag(d + "/tum.bag", tum, sample().frames, sample().imu);
	r = test::runCommand("'" + kImport + "' '" + d + "/tum.bag' -o '" + d +
	                     "/tum.rawlog' -q --layout tum");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("labelled ACCEL (no gyro)"), std::string::npos)
	    << r.out;
	r = test::runCommand("'" + kRun + "' '" + test::kDefaultConfig + "' '" + d +
	                     "/tum.rawlog' -o '" + d + "/runtum' -q");
	EXPECT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("ACCEL"), std::string::npos) << r.out;
}

TEST(ImportBag, ConfigKeysAreStrictAndThePresetSetsTheLayout)
{
	bag::BagImportParams p;
	p.loadFromConfigFile(
	    *openIniFile(test::kSourceDir + "/config/realsense.ini"));
	EXPECT_EQ(p.layout, bag::BagLayout::RealSense);
	EXPECT_FALSE(p.camera);  // the bag's CameraInfo
	const auto t = bag::resolveTopics(p.topics, p.layout);
	EXPECT_EQ(t.gyro, "/camera/gyro/sample");

	const auto d = test::freshTmpDir("bims_bag", "ini");
	bag::BagImportParams last;  // of the last file read
	auto errorFor = [&](const std::string& text)
	{
		{
			std::ofstream(d + "/x.ini") << text;
		}
		last = {};
		return errorOf(
		    [&] { last.loadFromConfigFile(*openIniFile(d + "/x.ini")); });
	};
	auto e = errorFor("[import_bag]\ndepth_topik = /d\n");
	EXPECT_NE(e.find("depth_topik"), std::string::npos) << e;
	EXPECT_NE(e.find("x.ini"), std::string::npos) << e;
	e = errorFor("[import_bag]\nlayout = kinect\n");
	EXPECT_NE(e.find("kinect"), std::string::npos) << e;
	e = errorFor("[import_bag]\naccel_label = ACC_SYNTH\n");
	EXPECT_NE(e.find("SYNTH"), std::string::npos) << e;
	e = errorFor("[camera]\nfx = 500\n");
	EXPECT_NE(e.find("all or none"), std::string::npos) << e;
	e = errorFor("[camera]\ndepth_scale = 5000\n");
	EXPECT_NE(e.find("REP 118"), std::string::npos) << e;

	// [camera] overrides the bag's CameraInfo; "none" drops a preset topic
	EXPECT_EQ(errorFor("[camera]\nfx = 500\nfy = 501\ncx = 160\ncy = 120\n"
	                   "width = 320\nheight = 240\n[import_bag]\n"
	                   "colour_topic = none\n"),
	          "(no error)");
	BagSpec spec;
	spec.frames = 3;
	writeBag(d + "/rs.bag", spec, sample().frames, sample().imu);
	const auto sum = import(d + "/rs.bag", d + "/o.rawlog", last);
	EXPECT_EQ(sum.camera.fy(), 501);
	EXPECT_NE(sum.cameraFrom.find("x.ini"), std::string::npos);
	EXPECT_TRUE(sum.topics.colour.empty());
	EXPECT_FALSE(readRawlog(d + "/o.rawlog").frames[0]->hasIntensityImage);
}

TEST(ImportBag, ABagWithoutTheTopicsListsTheTopicsItHas)
{
	const auto d = test::freshTmpDir("bims_bag", "topics");
	{
		rosbag::Bag b(d + "/other.bag", rosbag::bagmode::Write);
		b.write("/scan_cloud", ros::Time(1), imuMsg(*sample().imu[0], 1, 1));
	}
	const auto e = errorOf([&] { import(d + "/other.bag", d + "/o.rawlog"); });
	EXPECT_NE(e.find(d + "/other.bag"), std::string::npos) << e;
	EXPECT_NE(e.find("/scan_cloud"), std::string::npos) << e;
	EXPECT_NE(e.find("sensor_msgs/Imu"), std::string::npos) << e;
	EXPECT_FALSE(fs::exists(d + "/o.rawlog"));

	// a topic the .ini names must be there
	BagSpec spec;
	spec.frames = 3;
	writeBag(d + "/rs.bag", spec, sample().frames, sample().imu);
	bag::BagImportParams p;
	p.topics.colour = "/camera/rgb/nope";
	const auto e2 = errorOf([&] { import(d + "/rs.bag", d + "/o.rawlog", p); });
	EXPECT_NE(e2.find("no colour topic /camera/rgb/nope"), std::string::npos)
	    << e2;
	EXPECT_NE(e2.find("/camera/color/image_raw"), std::string::npos) << e2;
}

TEST(ImportBag, AWrongEncodingOrSizeIsAnErrorNamingTopicAndMessage)
{
	const auto d = test::freshTmpDir("bims_bag", "encoding");
	BagSpec spec;
	spec.frames = 3;
	spec.colour = "rgba8";
	writeBag(d + "/rgba.bag", spec, sample().frames, sample().imu);
	auto e = errorOf([&] { import(d + "/rgba.bag", d + "/o.rawlog"); });
	EXPECT_NE(e.find("/camera/color/image_raw, message #1"), std::string::npos)
	    << e;
	EXPECT_NE(e.find("'rgba8' is not supported"), std::string::npos) << e;
	EXPECT_FALSE(fs::exists(d + "/o.rawlog"));

	// a CameraInfo of another size than the images
	{
		rosbag::Bag b(d + "/info.bag", rosbag::bagmode::Write);
		const auto& f = *sample().frames[0];
		auto info = infoMsg(f);
		info.width = 640;
		const ros::Time t = rosTime(secondsOf(f.timestamp));
		b.write("/camera/color/camera_info", t, info);
		b.write("/camera/aligned_depth_to_color/image_raw", t,
		        depthMsg(f, false));
	}
	e = errorOf([&] { import(d + "/info.bag", d + "/o.rawlog"); });
	EXPECT_NE(e.find("the depth image is 320x240, the camera 640x240"),
	          std::string::npos)
	    << e;
}

TEST(ImportBag, ACorruptFrameKeepsTheWholeFramesBeforeIt)
{
	const auto d = test::freshTmpDir("bims_bag", "corrupt");
	{
		rosbag::Bag b(d + "/c.bag", rosbag::bagmode::Write);
		for (size_t k = 0; k < 5; k++)
		{
			const auto& f = *sample().frames[k];
			const ros::Time t = rosTime(secondsOf(f.timestamp));
			auto depth = depthMsg(f, false);
			if (k == 3) depth.data.resize(depth.data.size() / 2);
			b.write("/camera/color/camera_info", t, infoMsg(f));
			b.write("/camera/aligned_depth_to_color/image_raw", t, depth);
		}
	}
	const auto e = errorOf([&] { import(d + "/c.bag", d + "/c.rawlog"); });
	EXPECT_NE(e.find("message #4 of it"), std::string::npos) << e;
	EXPECT_NE(e.find("corrupt"), std::string::npos) << e;
	EXPECT_NE(e.find("the 3 whole frames before it are in"), std::string::npos)
	    << e;
	EXPECT_EQ(readRawlog(d + "/c.rawlog").frames.size(), 3u);
}

TEST(ImportBag, MissingAndForeignFilesAreClearErrors)
{
	const auto d = test::freshTmpDir("bims_bag", "files");
	auto e = errorOf([&] { import(d + "/none.bag", d + "/o.rawlog"); });
	EXPECT_NE(e.find("none.bag: no such bag"), std::string::npos) << e;
	{
		std::ofstream(d + "/text.bag") << "hello\n";
		std::ofstream(d + "/empty.bag");
	}
	for (const char* name : {"/text.bag", "/empty.bag"})
	{
		e = errorOf([&] { import(d + name, d + "/o.rawlog"); });
		EXPECT_NE(e.find(std::string(name).substr(1) +
		                 ": not a readable ROS 1 bag (it does not start "
		                 "with '#ROSBAG V2.0')"),
		          std::string::npos)
		    << e;
	}
	EXPECT_FALSE(fs::exists(d + "/o.rawlog"));
}

// A recording cut short (the recorder killed, the disk full, a download
// stopped) has no index: its messages are read from its chunks, and every
// whole frame before the cut is written, pixel for pixel the whole bag's;
// the error names the bag and the byte. With compressed chunks, the chunk
// the cut is in is lost whole.
TEST(ImportBag, ACutShortBagGivesEveryWholeFrameBeforeTheCut)
{
	const auto d = test::freshTmpDir("bims_bag", "cut");
	for (const auto& [compression, name] : std::vector<
	         std::pair<rosbag::compression::CompressionType, std::string>>{
	         {rosbag::compression::Uncompressed, "none"},
	         {rosbag::compression::LZ4, "lz4"},
	         {rosbag::compression::BZ2, "bz2"}})
	{
		SCOPED_TRACE(name);
		BagSpec spec;
		spec.frames = 8;
		spec.compression = compression;
		const std::string whole = d + "/" + name + ".bag";
		writeBag(whole, spec, sample().frames, sample().imu);
		const auto size = fs::file_size(whole);
		for (const double part : {0.5, 0.8})
		{
			const std::string cut = d + "/" + name + "_cut.bag";
			const std::string out = d + "/" + name + "_cut.rawlog";
			fs::copy_file(whole, cut, fs::copy_options::overwrite_existing);
			fs::resize_file(cut, static_cast<uintmax_t>(size * part));
			const auto e = errorOf([&] { import(cut, out); });
			EXPECT_NE(e.find(cut + ": cut short or damaged: the "),
			          std::string::npos)
			    << e;
			const Imported got = readRawlog(out);
			EXPECT_NE(e.find("; the " + std::to_string(got.frames.size()) +
			                 " whole frames before it are in " + out),
			          std::string::npos)
			    << e;
			EXPECT_GE(got.frames.size(), part < 0.6 ? 2u : 4u);
			// --topics: the topics before the cut, and the damage said
			std::vector<std::string> damage;
			const auto topics = bag::bagTopics({cut}, &damage);
			ASSERT_EQ(damage.size(), 1u);
			EXPECT_EQ(damage[0], e.substr(0, damage[0].size()));
			const auto depth = std::find_if(
			    topics.begin(), topics.end(),
			    [](const bag::BagTopicInfo& t) {
				    return t.name == "/camera/aligned_depth_to_color/image_raw";
			    });
			ASSERT_NE(depth, topics.end());
			EXPECT_GE(depth->messages, got.frames.size());
			EXPECT_LT(got.frames.size(), 8u);
			for (const auto& f : got.frames) f->load();
			expectTheSampleFrames(got, got.frames.size());
		}
	}
}

TEST(ImportBag, StampsThatGoBackAreLeftOutAndCounted)
{
	const auto d = test::freshTmpDir("bims_bag", "back");
	{
		rosbag::Bag b(d + "/back.bag", rosbag::bagmode::Write);
		for (size_t k : {0, 1, 2, 1, 3})  // the fourth goes back in time
		{
			const auto& f = *sample().frames[k];
			const ros::Time t = rosTime(secondsOf(f.timestamp));
			auto info = infoMsg(f);
			info.D[0] = 0.05;  // a lens distortion bims does not model
			b.write("/camera/color/camera_info", t, info);
			b.write("/camera/aligned_depth_to_color/image_raw", t,
			        depthMsg(f, false));
		}
	}
	const auto sum = import(d + "/back.bag", d + "/back.rawlog");
	EXPECT_EQ(sum.frames, 4u);
	EXPECT_EQ(sum.stampsBack, 1u);
	EXPECT_TRUE(sum.distortionIgnored);  // the report says it (apps)
	EXPECT_EQ(sum.distortionModel, "plumb_bob");
	EXPECT_TRUE(sum.topics.colour.empty());  // the preset's is absent
	const auto got = readRawlog(d + "/back.rawlog");
	ASSERT_EQ(got.frames.size(), 4u);
	EXPECT_FALSE(got.frames[0]->hasIntensityImage);
}

/** Imports \a spec's bag of the sample's first \a n frames (auto layout,
 * plain rawlog) into DIR/NAME.rawlog; returns the rawlog's bytes. */
std::string importedBytes(const std::string& dir, const std::string& name,
                          BagSpec spec, bag::BagImportSummary* sum = nullptr)
{
	writeBag(dir + "/" + name + ".bag", spec, sample().frames, sample().imu);
	const auto s =
	    import(dir + "/" + name + ".bag", dir + "/" + name + ".rawlog");
	if (sum) *sum = s;
	return test::fileText(dir + "/" + name + ".rawlog");
}

TEST(ImportBag, LosslessCompressedTopicsGiveTheRawTopicsRawlogByteForByte)
{
	const auto d = test::freshTmpDir("bims_bag", "compressed");
	// realsense-ros: raw topics, against PNG colour and compressedDepth
	// 16UC1 (PNG and RVL) on image_transport's republished topics (the auto
	// layout finds them); the colour format as the plugin writes it now,
	// and the old "png"
	BagSpec raw;
	raw.frames = 12;
	const std::string want = importedBytes(d, "raw", raw);
	ASSERT_GT(want.size(), 500000u);
	const std::pair<std::string, std::string> variants[] = {
	    {"", "png"}, {"png", "png"}, {"", "rvl"}};
	for (const auto& [format, depthCodec] : variants)
	{
		SCOPED_TRACE(format + " " + depthCodec);
		BagSpec c = raw;
		c.colourCodec = "png";
		c.colourFormat = format;
		c.compressedDepth = true;
		c.depthCodec = depthCodec;
		bag::BagImportSummary sum;
		const std::string got = importedBytes(d, "c", c, &sum);
		EXPECT_EQ(sum.layout, bag::BagLayout::RealSense);
		EXPECT_EQ(sum.topics.colour, "/camera/color/image_raw/compressed");
		EXPECT_EQ(sum.topics.depth,
		          "/camera/aligned_depth_to_color/image_raw/compressedDepth");
		EXPECT_EQ(sum.depthEncoding, "16UC1; compressedDepth " + depthCodec);
		EXPECT_EQ(sum.frames, 12u);
		EXPECT_TRUE(got == want)
		    << firstDifference(d + "/raw.rawlog", d + "/c.rawlog");
	}
	// TUM's layout: 32FC1 depth (raw: compressedDepth quantises it), PNG
	// colour
	BagSpec tum;
	tum.tum = true;
	tum.frames = 6;
	const std::string wantTum = importedBytes(d, "tumraw", tum);
	tum.colourCodec = "png";
	bag::BagImportSummary sum;
	EXPECT_TRUE(importedBytes(d, "tumc", tum, &sum) == wantTum)
	    << firstDifference(d + "/tumraw.rawlog", d + "/tumc.rawlog");
	EXPECT_EQ(sum.layout, bag::BagLayout::Tum);
	EXPECT_EQ(sum.colourEncoding, "rgb8; png compressed bgr8");
}

TEST(ImportBag, TheRawTopicIsReadWhenTheBagAlsoHasItsCompressedOne)
{
	const auto d = test::freshTmpDir("bims_bag", "both");
	const std::string depth = "/camera/aligned_depth_to_color/image_raw";
	{
		rosbag::Bag b(d + "/both.bag", rosbag::bagmode::Write);
		for (size_t k = 0; k < 3; k++)
		{
			const auto& f = *sample().frames[k];
			const ros::Time t = rosTime(secondsOf(f.timestamp));
			b.write("/camera/color/camera_info", t, infoMsg(f));
			b.write(depth, t, depthMsg(f, false));
			b.write(depth + "/compressedDepth", t,
			        compressedDepthMsg(f, false));
			b.write("/camera/color/image_raw/compressed", t,
			        compressedColourMsg(f, "jpeg"));
		}
	}
	// the preset's raw depth; its colour from /compressed (no raw one)
	auto sum = import(d + "/both.bag", d + "/o.rawlog");
	EXPECT_EQ(sum.topics.depth, depth);
	EXPECT_EQ(sum.depthEncoding, "16UC1");
	EXPECT_EQ(sum.topics.colour, "/camera/color/image_raw/compressed");
	EXPECT_EQ(sum.colourEncoding, "rgb8; jpeg compressed bgr8");
	EXPECT_EQ(sum.frames, 3u);
	// a topic the .ini names is read as named
	bag::BagImportParams p;
	p.layout = bag::BagLayout::RealSense;
	p.topics.depth = depth + "/compressedDepth";
	sum = import(d + "/both.bag", d + "/p.rawlog", p);
	EXPECT_EQ(sum.topics.depth, depth + "/compressedDepth");
	EXPECT_EQ(sum.depthEncoding, "16UC1; compressedDepth png");
}

TEST(ImportBag, JpegColourIsWithinASmallToleranceOfTheRawFrame)
{
	const auto d = test::freshTmpDir("bims_bag", "jpeg");
	BagSpec spec;
	spec.frames = 6;
	spec.colourCodec = "jpeg";
	spec.compressedDepth = true;
	importedBytes(d, "jpeg", spec);
	const auto got = readRawlog(d + "/jpeg.rawlog");
	ASSERT_EQ(got.frames.size(), 6u);
	for (size_t k = 0; k < 6; k++)
	{
		const auto& a = *got.frames[k];
		const auto& b = *sample().frames[k];
		EXPECT_TRUE((a.rangeImage.array() == b.rangeImage.array()).all());
		ASSERT_TRUE(a.hasIntensityImage);
		// what image_transport's subscriber gives (OpenCV's decoding of
		// the message), exactly
		std::vector<uint8_t> jpeg;
		cv::imencode(".jpg", bgrOf(b), jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
		cv::Mat diff;
		cv::absdiff(bgrOf(a), cv::imdecode(jpeg, cv::IMREAD_UNCHANGED), diff);
		EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0) << "frame " << k;
		// the raw frame within JPEG's loss (quality 90, chroma subsampled:
		// the simulated texture loses 4 to 8 levels on average)
		cv::absdiff(bgrOf(a), bgrOf(b), diff);
		const cv::Scalar mean = cv::mean(diff);
		for (int c = 0; c < 3; c++)
			EXPECT_LT(mean[c], 10.0) << "frame " << k << " channel " << c;
		EXPECT_GT(cv::PSNR(bgrOf(a), bgrOf(b)), 25.0) << "frame " << k;
		// with red and blue swapped it would be far off
		cv::Mat rgb;
		cv::cvtColor(bgrOf(b), rgb, cv::COLOR_BGR2RGB);
		cv::absdiff(bgrOf(a), rgb, diff);
		const cv::Scalar swapped = cv::mean(diff);
		EXPECT_GT(swapped[0] + swapped[2], 4 * (mean[0] + mean[2]));
	}
}

TEST(ImportBag, CompressedDepthInMetresIsWithinItsQuantisationStep)
{
	const auto d = test::freshTmpDir("bims_bag", "invdepth");
	BagSpec spec;
	spec.tum = true;
	spec.frames = 4;
	importedBytes(d, "raw", spec);
	spec.compressedDepth = true;
	bag::BagImportSummary sum;
	importedBytes(d, "c", spec, &sum);
	EXPECT_EQ(sum.depthEncoding, "32FC1; compressedDepth png");
	const auto a = readRawlog(d + "/raw.rawlog"),
	           b = readRawlog(d + "/c.rawlog");
	ASSERT_EQ(a.frames.size(), 4u);
	ASSERT_EQ(b.frames.size(), 4u);
	// the plugin's inverse depth, v = A / z + B truncated, gives back
	// A / (v - B) in [z, z + z^2 / A) (A = 10100 with its defaults); then
	// the rounding to millimetres
	const double A = 100.0 * 101.0;
	size_t readings = 0, off = 0;
	for (size_t k = 0; k < 4; k++)
	{
		const auto& ra = a.frames[k]->rangeImage;
		const auto& rb = b.frames[k]->rangeImage;
		for (int v = 0; v < ra.rows(); v++)
			for (int u = 0; u < ra.cols(); u++)
			{
				ASSERT_EQ(ra(v, u) == 0, rb(v, u) == 0) << v << " " << u;
				if (ra(v, u) == 0) continue;
				readings++;
				const double z = ra(v, u) * 1e-3;
				const double err = (rb(v, u) - double(ra(v, u))) * 1e-3;
				EXPECT_GE(err, -0.001);
				EXPECT_LE(err, z * z / A + 0.001) << z;
				off += rb(v, u) != ra(v, u);
			}
	}
	EXPECT_GT(readings, 100000u);
	EXPECT_GT(off, 0u);  // quantised indeed
	// the same inverse depth compressed by RVL: the PNG's rawlog, byte for
	// byte
	spec.depthCodec = "rvl";
	importedBytes(d, "rvl", spec, &sum);
	EXPECT_EQ(sum.depthEncoding, "32FC1; compressedDepth rvl");
	EXPECT_TRUE(test::fileText(d + "/rvl.rawlog") ==
	            test::fileText(d + "/c.rawlog"))
	    << firstDifference(d + "/c.rawlog", d + "/rvl.rawlog");
}

TEST(ImportBag, BadCompressedImagesAreErrorsNamingTopicAndMessage)
{
	const auto d = test::freshTmpDir("bims_bag", "badcompressed");
	const std::string colour = "/camera/color/image_raw/compressed",
	                  depth =
	                      "/camera/aligned_depth_to_color/image_raw/"
	                      "compressedDepth";
	// five frames; \a spoil changes the messages of frame k
	auto write =
	    [&](const std::string& name,
	        const std::function<void(size_t, sensor_msgs::CompressedImage&,
	                                 sensor_msgs::CompressedImage&)>& spoil)
	{
		rosbag::Bag b(d + "/" + name, rosbag::bagmode::Write);
		for (size_t k = 0; k < 5; k++)
		{
			const auto& f = *sample().frames[k];
			const ros::Time t = rosTime(secondsOf(f.timestamp));
			auto c = compressedColourMsg(f, "png");
			auto z = compressedDepthMsg(f, false);
			spoil(k, c, z);
			b.write("/camera/color/camera_info", t, infoMsg(f));
			b.write(colour, t, c);
			b.write(depth, t, z);
		}
		return d + "/" + name;
	};
	auto importError =
	    [&](const std::string& bagPath, bag::BagImportParams p = {})
	{
		fs::remove(d + "/o.rawlog");
		return errorOf([&] { import(bagPath, d + "/o.rawlog", p); });
	};
	// a corrupt payload: the whole frames before it are kept
	auto e = importError(write("cut.bag",
	                           [](size_t k, auto& c, auto&)
	                           {
		                           if (k == 3) c.data.resize(c.data.size() / 2);
	                           }));
	EXPECT_NE(e.find("cut.bag: topic " + colour + ", message #4 of it"),
	          std::string::npos)
	    << e;
	EXPECT_NE(e.find("do not decode as PNG"), std::string::npos) << e;
	EXPECT_NE(e.find("the 3 whole frames before it are in"), std::string::npos)
	    << e;
	EXPECT_EQ(readRawlog(d + "/o.rawlog").frames.size(), 3u);

	// a format image_transport does not write, an unsupported encoding
	e = importError(write("webp.bag", [](size_t, auto& c, auto&)
	                      { c.format = "rgb8; webp compressed bgr8"; }));
	EXPECT_NE(e.find("topic " + colour + ", message #1 of it"),
	          std::string::npos)
	    << e;
	EXPECT_NE(e.find("format 'rgb8; webp compressed bgr8' is none "
	                 "image_transport writes"),
	          std::string::npos)
	    << e;
	EXPECT_FALSE(fs::exists(d + "/o.rawlog"));
	e = importError(write("rgba.bag", [](size_t, auto& c, auto&)
	                      { c.format = "rgba8; png compressed bgra8"; }));
	EXPECT_NE(e.find("encoding 'rgba8' is not supported"), std::string::npos)
	    << e;
	// a JPEG where the format says PNG
	e = importError(write("jpegpng.bag",
	                      [&](size_t k, auto& c, auto&)
	                      {
		                      c = compressedColourMsg(*sample().frames[k],
		                                              "jpeg",
		                                              "rgb8; png compressed "
		                                              "bgr8");
	                      }));
	EXPECT_NE(e.find("a JPEG image, not PNG"), std::string::npos) << e;

	// compressedDepth: a header cut short, a truncated RVL stream, another
	// header format
	e = importError(write("header.bag",
	                      [](size_t k, auto&, auto& z)
	                      {
		                      if (k == 1) z.data.resize(7);
	                      }));
	EXPECT_NE(e.find("topic " + depth + ", message #2 of it"),
	          std::string::npos)
	    << e;
	EXPECT_NE(e.find("7 bytes of data: cut inside its 12-byte compressedDepth "
	                 "header"),
	          std::string::npos)
	    << e;
	EXPECT_NE(e.find("the 1 whole frames before it are in"), std::string::npos)
	    << e;
	e = importError(write("rvl.bag",
	                      [](size_t k, auto&, auto& z)
	                      {
		                      z = compressedDepthMsg(*sample().frames[k], false,
		                                             "rvl");
		                      if (k == 2) z.data.resize(z.data.size() - 4);
	                      }));
	EXPECT_NE(e.find("topic " + depth + ", message #3 of it"),
	          std::string::npos)
	    << e;
	EXPECT_NE(e.find("format '16UC1; compressedDepth rvl'"), std::string::npos)
	    << e;
	EXPECT_NE(e.find("ends early, at pixel "), std::string::npos) << e;
	EXPECT_NE(e.find("of 76800: corrupt"), std::string::npos) << e;
	EXPECT_NE(e.find("the 2 whole frames before it are in"), std::string::npos)
	    << e;
	e = importError(
	    write("kind.bag", [](size_t, auto&, auto& z) { z.data[0] = 7; }));
	EXPECT_NE(e.find("format is 7, not INV_DEPTH (0): corrupt"),
	          std::string::npos)
	    << e;
	e = importError(write("notdepth.bag", [](size_t, auto&, auto& z)
	                      { z.format = "16UC1; png compressed "; }));
	EXPECT_NE(e.find("not compressed_depth_image_transport's"),
	          std::string::npos)
	    << e;

	// a declared size other than the camera's, or beyond [input]'s limits:
	// refused before decoding
	e = importError(write("huge.bag",
	                      [](size_t, auto& c, auto&)
	                      {
		                      // IHDR's width and height: 30000 x 30000
		                      for (size_t at : {16, 20})
		                      {
			                      c.data[at] = 0;
			                      c.data[at + 1] = 0;
			                      c.data[at + 2] = 0x75;
			                      c.data[at + 3] = 0x30;
		                      }
	                      }));
	EXPECT_NE(e.find("its PNG header declares 30000x30000, the camera is "
	                 "320x240 (not decoded)"),
	          std::string::npos)
	    << e;
	{
		std::ofstream(d + "/limits.ini") << "[input]\nimage_max_side = 300\n";
	}
	bag::BagImportParams p;
	p.loadFromConfigFile(*openIniFile(d + "/limits.ini"));
	e = importError(write("fine.bag", [](size_t, auto&, auto&) {}), p);
	EXPECT_NE(e.find("topic " + depth + ", message #1 of it"),
	          std::string::npos)
	    << e;
	EXPECT_NE(e.find("beyond the 300 per side"), std::string::npos) << e;
	EXPECT_NE(e.find("[input] image_max_side"), std::string::npos) << e;
	EXPECT_NO_THROW(import(d + "/fine.bag", d + "/fine.rawlog"));
}

TEST(ImportBag, CompressedFormatsAreParsedAsTheImageTransportPluginsWriteThem)
{
	const auto f = bag::parseCompressedFormat("rgb8; jpeg compressed bgr8");
	EXPECT_EQ(f.encoding, "rgb8");
	EXPECT_EQ(f.codec, "jpeg");
	EXPECT_TRUE(f.bgr);
	EXPECT_FALSE(f.depth);
	EXPECT_FALSE(bag::parseCompressedFormat("rgb8; jpeg compressed").bgr);
	EXPECT_EQ(bag::parseCompressedFormat("png").codec, "png");
	EXPECT_TRUE(bag::parseCompressedFormat("png").encoding.empty());
	const auto z = bag::parseCompressedFormat("32FC1; compressedDepth");
	EXPECT_TRUE(z.depth);
	EXPECT_EQ(z.codec, "png");
	EXPECT_EQ(z.encoding, "32FC1");
	EXPECT_EQ(bag::parseCompressedFormat("16UC1; compressedDepth rvl").codec,
	          "rvl");
	for (const char* bad :
	     {"", "tiff", "jpeg png", "; png compressed bgr8", "rgb8; png",
	      "16UC1; compressedDepth zstd", "rgb8; png compressed bgr8 x"})
		EXPECT_NE(errorOf([&] { bag::parseCompressedFormat(bad); })
		              .find("is none image_transport writes"),
		          std::string::npos)
		    << bad;
}

/** A compressedDepth message of the 16-bit image \a v: 16UC1 millimetres
 * (\a encoding), as the plugin's \a codec ("png", "rvl") writes them. */
sensor_msgs::CompressedImage depthOf(const cv::Mat& v, const std::string& codec,
                                     const std::string& encoding = "16UC1")
{
	sensor_msgs::CompressedImage m;
	m.format = encoding + "; compressedDepth " + codec;
	const float quant[2] = {0, 0};
	m.data = compressedDepthData(v, codec, quant);
	return m;
}

/** A W x H depth image of holes (zeros, single and in runs, at both ends),
 * jumps across the whole 16-bit range, smooth stretches and noise. */
cv::Mat holesAndJumps(int W, int H, uint32_t seed)
{
	std::mt19937 rng(seed);
	cv::Mat v(H, W, CV_16UC1);
	for (int r = 0; r < H; r++)
		for (int c = 0; c < W; c++)
		{
			const int i = r * W + c;
			uint16_t x = static_cast<uint16_t>(1000 + 3 * c + r);
			switch (rng() % 8)
			{
				case 0:
					x = 0;
					break;
				case 1:
					x = 65535;
					break;
				case 2:
					x = 1;
					break;
				case 3:
					x = static_cast<uint16_t>(rng());
					break;
				default:
					break;
			}
			if (i < 5 || i >= W * H - 7 || (r == 3 && c > 2)) x = 0;
			v.at<uint16_t>(r, c) = x;
		}
	return v;
}

bool samePixels(const cv::Mat& a, const cv::Mat& b)
{
	return a.type() == b.type() && a.size() == b.size() &&
	       cv::countNonZero(a != b) == 0;
}

// The plugin's stream, worked by hand from its algorithm: nibbles of 3 bits
// (lowest first, the 4th bit: more follow) filling 32-bit words from the
// high end; the runs of zeros and readings, the zig-zagged differences.
TEST(ImportBag, RvlRunsAndNumbersArePackedAsThePluginWritesThem)
{
	struct Case
	{
		std::vector<uint16_t> px;
		uint32_t word;
	};
	const Case cases[] = {
	    // 2 zeros, 2 readings: 5 (+5: 10 = 2 | 8, 1), 7 (+2: 4); padding
	    {{0, 0, 5, 7}, 0x22A14000},
	    // 0 zeros, 2 readings: 3 (+3: 6), 1 (-2: 3)
	    {{3, 1}, 0x02630000},
	    // 0 zeros, 1 reading: 4 (+4: 8 = 0 | 8, 1); 2 zeros, 0 readings
	    {{4, 0, 0}, 0x01812000},
	};
	for (const auto& c : cases)
	{
		std::vector<uint8_t> want(4);
		std::memcpy(want.data(), &c.word, 4);  // the writer's byte order
		EXPECT_EQ(rvlEncoded(c.px.data(), c.px.size()), want)
		    << std::hex << c.word;
		const int W = static_cast<int>(c.px.size());
		const cv::Mat v(1, W, CV_16UC1, const_cast<uint16_t*>(c.px.data()));
		EXPECT_TRUE(samePixels(
		    bag::decodeCompressedDepth(depthOf(v, "rvl"), W, 1, {}), v))
		    << std::hex << c.word;
	}
	// numbers of several nibbles: 64 (0 | 8, 0 | 8, 1), 9 (1 | 8, 1)
	RvlWriter w;
	w.number(64);
	w.number(9);
	const uint32_t word = 0x88191000;
	std::vector<uint8_t> want(4);
	std::memcpy(want.data(), &word, 4);
	EXPECT_EQ(w.finish(), want);
}

TEST(ImportBag, RvlDepthDecodesToTheOriginalPixelForPixel)
{
	// the sample's frames, as the PNG codec gives them too
	for (size_t k = 0; k < 3; k++)
	{
		const auto& f = *sample().frames[k];
		sensor_msgs::Image raw = depthMsg(f, false);
		const cv::Mat v(240, 320, CV_16UC1, raw.data.data());
		const cv::Mat rvl =
		    bag::decodeCompressedDepth(depthOf(v, "rvl"), 320, 240, {});
		EXPECT_TRUE(samePixels(rvl, v)) << "frame " << k;
		EXPECT_TRUE(samePixels(
		    rvl, bag::decodeCompressedDepth(depthOf(v, "png"), 320, 240, {})));
	}
	// holes, jumps between 0, 1 and 65535, sizes of no whole word
	const std::pair<int, int> sizes[] = {{37, 11}, {1, 1}, {64, 48}, {5, 3}};
	for (const auto& [W, H] : sizes)
		for (uint32_t seed = 1; seed <= 20; seed++)
		{
			const cv::Mat v = holesAndJumps(W, H, seed);
			EXPECT_TRUE(samePixels(
			    bag::decodeCompressedDepth(depthOf(v, "rvl"), W, H, {}), v))
			    << W << "x" << H << " seed " << seed;
		}
	// one run each: no reading, all readings alike, the largest jump on
	// every pixel; mono16 as 16UC1
	cv::Mat zeros = cv::Mat::zeros(48, 64, CV_16UC1),
	        flat(48, 64, CV_16UC1, cv::Scalar(4321));
	cv::Mat zigzag(48, 64, CV_16UC1);
	for (int i = 0; i < 48 * 64; i++)
		zigzag.at<uint16_t>(i / 64, i % 64) = i % 2 ? 1 : 65535;
	for (const cv::Mat* v : {&zeros, &flat, &zigzag})
		EXPECT_TRUE(samePixels(bag::decodeCompressedDepth(
		                           depthOf(*v, "rvl", "mono16"), 64, 48, {}),
		                       *v));
}

TEST(ImportBag, RvlInverseDepthInMetresDecodesAsThePngOfIt)
{
	for (size_t k = 0; k < 3; k++)
	{
		// the sample's metres, with holes: no reading (0, NaN), beyond the
		// plugin's depth_max (10 m)
		const auto& f = *sample().frames[k];
		sensor_msgs::Image raw = depthMsg(f, true);
		cv::Mat z = cv::Mat(240, 320, CV_32FC1, raw.data.data()).clone();
		z(cv::Rect(0, 0, 40, 3)).setTo(0);
		z(cv::Rect(100, 50, 7, 60)).setTo(NAN);
		z(cv::Rect(300, 230, 20, 10)).setTo(12.5);
		float quant[2];
		const cv::Mat v = quantisedInverseDepth(z, quant);
		sensor_msgs::CompressedImage png, rvl;
		png.format = "32FC1; compressedDepth png";
		rvl.format = "32FC1; compressedDepth rvl";
		png.data = compressedDepthData(v, "png", quant);
		rvl.data = compressedDepthData(v, "rvl", quant);
		const cv::Mat a = bag::decodeCompressedDepth(png, 320, 240, {}),
		              b = bag::decodeCompressedDepth(rvl, 320, 240, {});
		ASSERT_EQ(b.type(), CV_32FC1);
		ASSERT_EQ(a.size(), b.size());
		// bit for bit: the same readings, NaN (no reading) at the same
		// pixels
		EXPECT_EQ(std::memcmp(a.data, b.data, a.total() * 4), 0)
		    << "frame " << k;
		const auto* p = a.ptr<float>();
		const auto holes = std::count_if(p, p + a.total(),
		                                 [](float x) { return std::isnan(x); });
		EXPECT_GE(holes, 40 * 3 + 7 * 60 + 20 * 10) << "frame " << k;
		EXPECT_LT(holes, 320 * 240 / 10) << "frame " << k;
		// as the bag writer's messages of the frame
		EXPECT_EQ(compressedDepthMsg(f, true, "rvl").format,
		          "32FC1; compressedDepth rvl");
		const cv::Mat c = bag::decodeCompressedDepth(
		                  compressedDepthMsg(f, true, "png"), 320, 240, {}),
		              d = bag::decodeCompressedDepth(
		                  compressedDepthMsg(f, true, "rvl"), 320, 240, {});
		EXPECT_EQ(std::memcmp(c.data, d.data, c.total() * 4), 0)
		    << "frame " << k;
	}
}

TEST(ImportBag, CorruptRvlStreamsAreErrorsNotCrashes)
{
	const cv::Mat v = holesAndJumps(32, 24, 7);
	const auto good = depthOf(v, "rvl");
	auto decodeError = [](const sensor_msgs::CompressedImage& m, int W = 32,
	                      int H = 24, const ImageLimits& limits = {})
	{ return errorOf([&] { bag::decodeCompressedDepth(m, W, H, limits); }); };
	auto spoilt = [&](const std::function<void(std::vector<uint8_t>&)>& f)
	{
		auto m = good;
		f(m.data);
		return decodeError(m);
	};
	auto expectIn = [](const std::string& e, const std::string& what)
	{
		EXPECT_NE(e.find("the depth image (CompressedImage, format '16UC1; "
		                 "compressedDepth rvl'): "),
		          std::string::npos)
		    << e;
		EXPECT_NE(e.find(what), std::string::npos) << e;
	};
	const size_t n = good.data.size() - 20;  // the stream's bytes
	ASSERT_EQ(decodeError(good), "(no error)");

	// the header or the image's size cut; no stream
	expectIn(spoilt([](auto& d) { d.resize(17); }),
	         "17 bytes of data: cut inside the RVL image's size (uint32 "
	         "cols, rows) after its 12-byte compressedDepth header");
	expectIn(spoilt([](auto& d) { d.resize(9); }),
	         "9 bytes of data: cut inside its 12-byte compressedDepth header");
	expectIn(spoilt([](auto& d) { d.resize(20); }),
	         "its RVL stream (0 bytes) ends early, at pixel 0 of 768: "
	         "corrupt");
	// truncated by a word, by a byte
	for (size_t cut : {4, 1})
		expectIn(spoilt([&](auto& d) { d.resize(d.size() - cut); }),
		         mrpt::format("its RVL stream (%zu bytes) ends early, at "
		                      "pixel ",
		                      n - cut));
	// a size other than the camera's, not decoded
	expectIn(spoilt([](auto& d) { d[12] = 33; }),
	         "its RVL header declares 33x24, the camera is 32x24 (not "
	         "decoded)");
	expectIn(spoilt([](auto& d) { std::swap(d[12], d[16]); }),
	         "its RVL header declares 24x32, the camera is 32x24");
	// a camera's size beyond the limits: refused before any allocation
	{
		auto m = good;
		const uint32_t side = 100000;
		std::memcpy(&m.data[12], &side, 4);
		std::memcpy(&m.data[16], &side, 4);
		expectIn(decodeError(m, 100000, 100000),
		         "declares 100000 x 100000 pixels in its RVL header, beyond "
		         "the 16384 per side");
	}

	// a stream of more pixels than the image's, of fewer, or going on
	auto ofSize = [](const cv::Mat& img)
	{
		auto m = depthOf(img, "rvl");
		const uint32_t size[2] = {32, 24};
		std::memcpy(&m.data[12], size, 8);
		return m;
	};
	const cv::Mat readings(25, 32, CV_16UC1, cv::Scalar(900));
	expectIn(decodeError(ofSize(readings)),
	         "has a run of 800 readings where 768 pixels are left, at pixel 0 "
	         "of 768: corrupt");
	cv::Mat thenZeros = readings.clone();
	thenZeros.row(24).setTo(0);
	expectIn(decodeError(ofSize(thenZeros)),
	         "goes on after the image's last pixel: corrupt");
	cv::Mat zerosLast(25, 32, CV_16UC1, cv::Scalar(900));
	zerosLast.rowRange(23, 25).setTo(0);
	expectIn(decodeError(ofSize(zerosLast)),
	         "has a run of 64 zeros where 32 pixels are left, at pixel 736 of "
	         "768: corrupt");
	expectIn(decodeError(ofSize(readings.rowRange(0, 23))),
	         "ends early, at pixel 736 of 768: corrupt");
	expectIn(spoilt([](auto& d) { d.insert(d.end(), 4, 0x11); }),
	         "goes on after the image's last pixel: corrupt");
	{
		// its padding not zero
		const uint16_t px[4] = {0, 0, 5, 7};
		auto m =
		    depthOf(cv::Mat(1, 4, CV_16UC1, const_cast<uint16_t*>(px)), "rvl");
		uint32_t word = 0;
		std::memcpy(&word, &m.data[20], 4);
		word ^= 1;  // the last of its 3 nibbles of padding
		std::memcpy(&m.data[20], &word, 4);
		EXPECT_NE(decodeError(m, 4, 1).find("goes on after the image's last "
		                                    "pixel: corrupt"),
		          std::string::npos);
	}

	// numbers no writer writes: a difference to a reading of 0 or beyond
	// 16 bits, a number of 12 nibbles
	auto ofWords = [](std::vector<uint32_t> words, uint32_t W)
	{
		sensor_msgs::CompressedImage m;
		m.format = "16UC1; compressedDepth rvl";
		m.data.assign(12, 0);
		const uint32_t size[2] = {W, 1};
		m.data.resize(20 + 4 * words.size());
		std::memcpy(&m.data[12], size, 8);
		std::memcpy(&m.data[20], words.data(), 4 * words.size());
		return m;
	};
	expectIn(decodeError(ofWords({0x01000000}, 4), 4, 1),
	         "gives a reading of 0 (a difference of 0 from 0) at pixel 0 of 4: "
	         "corrupt");
	expectIn(
	    decodeError(ofWords({0x01888884}, 1), 1, 1),
	    "gives a reading of 65536 (a difference of 65536 from 0) at pixel 0 "
	    "of 1");
	expectIn(
	    decodeError(ofWords({0x02A1B100}, 2), 2, 1),
	    "gives a reading of -1 (a difference of -6 from 5) at pixel 1 of 2");
	expectIn(decodeError(ofWords({0x0FFFFFFF, 0xFFFFFFFF}, 4), 4, 1),
	         "has a number of more than 11 nibbles at pixel 0 of 4: corrupt");

	// random bytes after a valid size, and the valid stream with a byte
	// changed: an error or an image, never more (the sanitizer build)
	std::mt19937 rng(35);
	for (int i = 0; i < 3000; i++)
	{
		auto m = good;
		if (i % 2)
			m.data[20 + rng() % n] = static_cast<uint8_t>(rng());
		else
		{
			m.data.resize(20 + rng() % 64);
			for (size_t b = 20; b < m.data.size(); b++)
				m.data[b] = static_cast<uint8_t>(rng());
		}
		const std::string e = decodeError(m);
		EXPECT_TRUE(e == "(no error)" || e.find(": corrupt") != e.npos) << e;
	}
}

/** The bytes of \a path with the 4 bytes after the first \a field (a
 * "name=" of a record header) from byte \a from on set to \a v; the
 * field's position. */
size_t patchField(const std::string& path, const std::string& field, uint32_t v,
                  size_t from = 0)
{
	std::string b = test::fileText(path);
	const size_t at = b.find(field, from);
	if (at == std::string::npos) return at;
	std::memcpy(&b[at + field.size()], &v, 4);
	std::ofstream(path, std::ios::binary) << b;
	return at;
}

// The index at a bag's end is not read for the messages (fuzz finding
// segv-index-offset-beyond-chunk: rosbag read a record header wherever an
// index entry pointed): index entries pointing anywhere, or an index record
// damaged, give the whole bag's rawlog byte for byte, the latter with a
// note.
TEST(ImportBag, TheMessagesAreReadFromTheChunksNotTheIndex)
{
	const auto d = test::freshTmpDir("bims_bag", "index");
	BagSpec spec;
	spec.frames = 3;
	spec.compression = rosbag::compression::LZ4;
	writeBag(d + "/ok.bag", spec, sample().frames, sample().imu);
	const std::string ok = test::fileText(d + "/ok.bag");
	import(d + "/ok.bag", d + "/ok.rawlog");
	const std::string want = test::fileText(d + "/ok.rawlog");
	const auto u32 = [&](size_t at)
	{
		uint32_t v = 0;
		std::memcpy(&v, &ok[at], 4);
		return size_t{v};
	};
	// every index data record's entries: their offsets
	std::string spoilt = ok;
	size_t entries = 0;
	for (size_t pos = ok.find('\n') + 1; pos + 8 < ok.size();)
	{
		const size_t hl = u32(pos), dl = u32(pos + 4 + hl);
		const std::string header = ok.substr(pos + 4, hl);
		if (header.find(std::string("op=\x04", 4)) != std::string::npos)
			for (size_t e = 0; e + 12 <= dl; e += 12, entries++)
			{
				const uint32_t offset = 0x7fffffffu;
				std::memcpy(&spoilt[pos + 8 + hl + e + 8], &offset, 4);
			}
		pos += 8 + hl + dl;
	}
	ASSERT_GT(entries, 3u);
	std::ofstream(d + "/entries.bag", std::ios::binary) << spoilt;
	auto sum = import(d + "/entries.bag", d + "/entries.rawlog");
	EXPECT_TRUE(sum.notes.empty());
	EXPECT_EQ(test::fileText(d + "/entries.rawlog"), want);

	// the first record at the index position: its header length
	spoilt = ok;
	const size_t f = spoilt.find("index_pos=");
	ASSERT_NE(f, std::string::npos);
	uint64_t indexPos = 0;
	std::memcpy(&indexPos, &spoilt[f + 10], 8);
	ASSERT_LT(indexPos + 4, spoilt.size());
	const uint32_t huge = 0xffffffffu;
	std::memcpy(&spoilt[indexPos], &huge, 4);
	std::ofstream(d + "/index.bag", std::ios::binary) << spoilt;
	sum = import(d + "/index.bag", d + "/index.rawlog");
	ASSERT_EQ(sum.notes.size(), 1u);
	EXPECT_NE(sum.notes[0].find("index.bag: its index at its end is damaged "
	                            "(the record at byte " +
	                            std::to_string(indexPos) +
	                            ": its header declares 4294967295 bytes"),
	          std::string::npos)
	    << sum.notes[0];
	EXPECT_EQ(test::fileText(d + "/index.rawlog"), want);
}

// A compressed chunk is decompressed once when the bag's chunks fit the
// cache; beyond it, again when its images are read: the same rawlog.
TEST(ImportBag, ABagBeyondTheChunkCacheGivesTheSameRawlog)
{
	const auto d = test::freshTmpDir("bims_bag", "cache");
	for (const auto compression :
	     {rosbag::compression::LZ4, rosbag::compression::BZ2})
	{
		BagSpec spec;
		spec.frames = 6;
		spec.compression = compression;
		writeBag(d + "/c.bag", spec, sample().frames, sample().imu);
		std::vector<std::string> rawlogs;
		for (const size_t cache : {size_t{1} << 30, size_t{300000}, size_t{0}})
		{
			bag::BagImportOptions o;
			o.gzLevel = 0;
			o.chunkCacheBytes = cache;
			const std::string out = d + "/" + std::to_string(cache) + ".rawlog";
			bag::importBag({d + "/c.bag"}, out, {}, o);
			rawlogs.push_back(test::fileText(out));
		}
		EXPECT_EQ(rawlogs[1], rawlogs[0]);
		EXPECT_EQ(rawlogs[2], rawlogs[0]);
		Imported got = readRawlog(d + "/0.rawlog");
		for (const auto& f : got.frames) f->load();
		expectTheSampleFrames(got, 6);
	}
}

TEST(ImportBag, LengthsBeyondTheFileAreErrorsNotAllocations)
{
	// rosbag_storage allocated what a record declares before reading it
	// (fuzz finding oom-record-header-length: 4 GB): every length is
	// checked against the bytes there are
	const auto d = test::freshTmpDir("bims_bag", "lengths");
	BagSpec spec;
	spec.frames = 3;
	spec.compression = rosbag::compression::LZ4;
	writeBag(d + "/ok.bag", spec, sample().frames, sample().imu);
	auto importError = [&](const std::string& bagPath)
	{ return errorOf([&] { import(bagPath, d + "/o.rawlog"); }); };

	// a chunk declaring 3.75 GB uncompressed
	fs::copy_file(d + "/ok.bag", d + "/chunk.bag");
	const size_t lz4 = test::fileText(d + "/chunk.bag").find("compression=lz4");
	ASSERT_NE(lz4, std::string::npos);
	ASSERT_NE(patchField(d + "/chunk.bag", "size=", 0xf0000000u, lz4),
	          std::string::npos);
	auto e = importError(d + "/chunk.bag");
	EXPECT_NE(e.find("a chunk of 4026531840 bytes uncompressed, beyond 1 GiB"),
	          std::string::npos)
	    << e;
	// a header field longer than its header
	fs::copy_file(d + "/ok.bag", d + "/field.bag");
	{
		std::string b = test::fileText(d + "/field.bag");
		const size_t at = b.find("compression=lz4");
		const uint32_t huge = 100000;
		std::memcpy(&b[at - 4], &huge, 4);  // the field's length
		std::ofstream(d + "/field.bag", std::ios::binary) << b;
	}
	e = importError(d + "/field.bag");
	EXPECT_NE(e.find("a header field declares 100000 bytes"), std::string::npos)
	    << e;
	// rosbag took any "#ROS<word> V2.0" line for a bag (fuzz finding
	// asan-version-line-header-field: its header was then read past its
	// end): only "#ROSBAG V2.0" is; other versions are refused
	{
		std::string b = test::fileText(d + "/ok.bag");
		b[6] = 'F';  // #ROSBAF
		const uint32_t huge = 100000;
		std::memcpy(&b[13 + 4], &huge, 4);  // the first field's length
		std::ofstream(d + "/baf.bag", std::ios::binary) << b;
		b = test::fileText(d + "/ok.bag");
		b.replace(9, 3, "1.2");
		std::ofstream(d + "/v12.bag", std::ios::binary) << b;
	}
	e = importError(d + "/baf.bag");
	EXPECT_NE(e.find("baf.bag: not a readable ROS 1 bag"), std::string::npos)
	    << e;
	e = importError(d + "/v12.bag");
	EXPECT_NE(e.find("bag format 1.2 (its first line): only 2.0"),
	          std::string::npos)
	    << e;
	EXPECT_FALSE(fs::exists(d + "/o.rawlog"));
	EXPECT_NO_THROW(import(d + "/ok.bag", d + "/ok.rawlog"));
}

TEST(ImportBag, AMessageArrayLongerThanItsMessageIsAnErrorNotAnAllocation)
{
	// ROS's deserializer resizes a vector to the length a message declares
	// before reading it (fuzz finding oom-compressed-image-data-length:
	// 1.9 GB): checked against the message's bytes first
	const auto d = test::freshTmpDir("bims_bag", "arrays");
	auto spoil = [&](const std::string& name, const BagSpec& spec,
	                 const std::string& before, long skip)
	{
		writeBag(d + "/" + name, spec, sample().frames, sample().imu);
		std::string b = test::fileText(d + "/" + name);
		const size_t at = b.find(before);
		EXPECT_NE(at, std::string::npos) << before;
		if (at == std::string::npos) return std::string();
		const uint32_t huge = 0x70000000u;
		std::memcpy(&b[at + before.size() + skip], &huge, 4);  // (skip < 0:
		                                                       // in before)
		std::ofstream(d + "/" + name, std::ios::binary) << b;
		return errorOf([&] { import(d + "/" + name, d + "/o.rawlog"); });
	};
	BagSpec c;
	c.frames = 2;
	c.colourCodec = "png";
	c.compressedDepth = true;
	// the first colour message's data: after its format string
	auto e = spoil("compressed.bag", c, "rgb8; png compressed bgr8", 0);
	EXPECT_NE(e.find("/camera/color/image_raw/compressed, message #1 of it"),
	          std::string::npos)
	    << e;
	EXPECT_NE(e.find("its data declares 1879048192 bytes, the message has"),
	          std::string::npos)
	    << e;
	// a raw depth image's data: after its encoding, is_bigendian and step
	BagSpec r;
	r.frames = 2;
	e = spoil("raw.bag", r, "16UC1", 5);
	EXPECT_NE(e.find("/camera/aligned_depth_to_color/image_raw, message #1"),
	          std::string::npos)
	    << e;
	EXPECT_NE(e.find("its data declares 1879048192 bytes"), std::string::npos)
	    << e;
	// CameraInfo's D (5 coefficients): after its distortion model (the
	// message definition's text has the name too)
	e = spoil("info.bag", r, std::string("plumb_bob\x05\0\0\0", 13), -4);
	EXPECT_NE(e.find("/camera/color/camera_info, message #1 of it cannot be "
	                 "read: its D declares 15032385536 bytes"),
	          std::string::npos)
	    << e;
}

TEST(ImportBag, AMessageOfAnotherMd5SumThanItsTypeIsAnErrorNotANullMessage)
{
	// a connection of type sensor_msgs/Imu whose MD5 sum is another's:
	// rosbag gives no message (fuzz finding ub-imu-of-another-md5: a null
	// message was read, undefined behaviour)
	const auto d = test::freshTmpDir("bims_bag", "md5");
	BagSpec spec;
	spec.frames = 2;
	writeBag(d + "/imu.bag", spec, sample().frames, sample().imu);
	std::string b = test::fileText(d + "/imu.bag");
	const std::string md5 = ros::message_traits::md5sum<sensor_msgs::Imu>();
	size_t n = 0;
	for (size_t at = b.find(md5); at != std::string::npos;
	     at = b.find(md5, at + 1), n++)
		b[at] = b[at] == '0' ? '1' : '0';
	ASSERT_GT(n, 0u);
	std::ofstream(d + "/imu.bag", std::ios::binary) << b;
	const auto e = errorOf([&] { import(d + "/imu.bag", d + "/o.rawlog"); });
	EXPECT_NE(e.find("topic /camera/imu, message #1 of it cannot be read: "
	                 "not a sensor_msgs/Imu: its MD5 sum"),
	          std::string::npos)
	    << e;
}

}  // namespace
