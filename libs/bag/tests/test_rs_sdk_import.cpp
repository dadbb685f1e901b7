// bims-import-bag --layout rs-sdk against RealSense SDK recordings the tests
// write themselves with the rosbag API (tests/support/bims_test/
// bag_writer.h: librealsense's documented layout, not bims's reader) from
// the bundled sample's frames and IMU: every pixel, stamp, unit,
// intrinsic and IMU axis against the sample and against the realsense-ros
// import of the same frames; the depth registered to a colour camera
// elsewhere; the extrinsics round trip into OUT_gt/calibration.ini; bims-run
// on the result; and the bad recordings users meet.
#include <bims/bag/bag_import.h>
#include <bims/io/rawlog.h>
#include <bims/sensors/params.h>
#include <bims_test/bag_writer.h>
#include <bims_test/error_of.h>
#include <bims_test/observations.h>
#include <bims_test/run_command.h>
#include <bims_test/sample.h>
#include <bims_test/text.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <functional>

namespace
{
namespace fs = std::filesystem;
using namespace bims;
using namespace bims::test;
using mrpt::obs::CObservation3DRangeScan;
using mrpt::obs::CObservationIMU;

const std::string kImport = std::string(BIMS_BIN_DIR) + "/bims-import-bag";
const std::string kRun = std::string(BIMS_BIN_DIR) + "/bims-run";

using Sample = test::Observations;

/** The sample's first 24 frames and their IMU samples. */
const Sample& sample()
{
	return test::sampleObservations();
}

Sample readRawlog(const std::string& path)
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

bool contains(const std::string& s, const std::string& part)
{
	return s.find(part) != std::string::npos;
}

/** The sample's mounting of its IMU (its OUT_gt/calibration.ini): p_I =
 * R_IC p_C, with a lever arm: the motion module's tf from the depth. */
bag::RigidTransform sampleImuTf()
{
	mrpt::config::CConfigFile cal(test::kSampleGt + "calibration.ini");
	sensors::CalibrationParams c;
	c.loadFromConfigFile(cal);
	bag::RigidTransform T;
	for (int i = 0; i < 9; i++) T.R[i] = c.R_IC(i / 3, i % 3);
	T.t[0] = -0.0052;
	T.t[1] = 0.0051;
	T.t[2] = 0.0117;
	return T;
}

/** A small rotation (about y then x) and a translation. */
bag::RigidTransform colourTf(double deg, double tx)
{
	const Eigen::Matrix3d R =
	    (Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d::UnitY()) *
	     Eigen::AngleAxisd(deg * M_PI / 360, Eigen::Vector3d::UnitX()))
	        .toRotationMatrix();
	bag::RigidTransform T;
	for (int i = 0; i < 9; i++) T.R[i] = R(i / 3, i % 3);
	T.t[0] = tx;
	T.t[1] = 0.001;
	T.t[2] = -0.002;
	return T;
}

void expectTransformNear(const bag::RigidTransform& a,
                         const bag::RigidTransform& b, double tol)
{
	for (int i = 0; i < 9; i++) EXPECT_NEAR(a.R[i], b.R[i], tol) << i;
	for (int i = 0; i < 3; i++) EXPECT_NEAR(a.t[i], b.t[i], tol) << i;
}

/** Every frame equals the sample's: range image, colour, stamp, camera. */
void expectTheSampleFrames(const Sample& got, size_t n)
{
	const auto& s = sample();
	ASSERT_EQ(got.frames.size(), n);
	for (size_t k = 0; k < n; k++)
	{
		const auto& a = *got.frames[k];
		const auto& b = *s.frames[k];
		EXPECT_NEAR(secondsOf(a.timestamp), secondsOf(b.timestamp), 1.1e-6);
		EXPECT_FLOAT_EQ(a.rangeUnits, 0.001f);
		ASSERT_EQ(a.rangeImage.rows(), b.rangeImage.rows());
		ASSERT_EQ(a.rangeImage.cols(), b.rangeImage.cols());
		EXPECT_TRUE((a.rangeImage.array() == b.rangeImage.array()).all())
		    << "frame " << k;
		EXPECT_DOUBLE_EQ(a.cameraParams.fx(), b.cameraParams.fx());
		EXPECT_DOUBLE_EQ(a.cameraParams.fy(), b.cameraParams.fy());
		EXPECT_DOUBLE_EQ(a.cameraParams.cx(), b.cameraParams.cx());
		EXPECT_DOUBLE_EQ(a.cameraParams.cy(), b.cameraParams.cy());
		ASSERT_TRUE(a.hasIntensityImage);
		cv::Mat d;
		cv::absdiff(bgrOf(a), bgrOf(b), d);
		EXPECT_EQ(cv::countNonZero(d.reshape(1)), 0) << "frame " << k;
	}
}

TEST(RsSdkImport, EveryPixelStampUnitIntrinsicAndImuAxisOfTheSample)
{
	const auto d = test::freshTmpDir("bims_rs_sdk", "sample");
	RsSdkSpec spec;
	spec.units = 0.0005f;  // 2 units a millimetre
	spec.unitsOption = "Depth_Units";
	spec.imuTf = sampleImuTf();
	writeRsSdkBag(d + "/sdk.bag", spec, sample().frames, sample().imu);

	bag::BagImportParams p;
	p.layout = bag::BagLayout::RsSdk;
	const auto sum = import(d + "/sdk.bag", d + "/sdk.rawlog", p);
	EXPECT_EQ(sum.layout, bag::BagLayout::RsSdk);
	EXPECT_EQ(sum.frames, 24u);
	EXPECT_EQ(sum.topics.depth, "/device_0/sensor_0/Depth_0/image/data");
	EXPECT_EQ(sum.topics.colour, "/device_0/sensor_1/Color_0/image/data");
	EXPECT_EQ(sum.topics.gyro, "/device_0/sensor_2/Gyro_0/imu/data");
	EXPECT_EQ(sum.depthEncoding, "mono16");
	EXPECT_FLOAT_EQ(static_cast<float>(sum.depthUnits), 0.0005f);
	EXPECT_TRUE(contains(sum.depthUnitsFrom, "option/Depth_Units/value"))
	    << sum.depthUnitsFrom;
	EXPECT_EQ(sum.cameraFrom,
	          "CameraInfo /device_0/sensor_1/Color_0/info/camera_info");
	const Sample got = readRawlog(d + "/sdk.rawlog");
	expectTheSampleFrames(got, 24);

	// accel and gyro merged at the gyro's stamps, every axis the sample's
	const auto& s = sample();
	const double t0 = secondsOf(s.frames.front()->timestamp),
	             t1 = secondsOf(s.frames[23]->timestamp);
	std::vector<CObservationIMU::Ptr> direct;
	for (const auto& m : s.imu)
		if (secondsOf(m->timestamp) >= t0 - 1e-6 &&
		    secondsOf(m->timestamp) <= t1 + 1e-6)
			direct.push_back(m);
	using namespace mrpt::obs;
	ASSERT_GE(got.imu.size() + 1, direct.size());
	ASSERT_LE(got.imu.size(), direct.size());
	ASSERT_GT(got.imu.size(), 50u);
	// the accelerometer was written at every other gyro sample: where it
	// was, the merged sample is exactly it
	size_t firstIndex = 0;
	while (secondsOf(s.imu[firstIndex]->timestamp) < t0 - 1e-6) firstIndex++;
	for (size_t i = 0; i < got.imu.size(); i++)
	{
		const auto& g = *got.imu[i];
		EXPECT_EQ(g.sensorLabel, "IMU");
		EXPECT_NEAR(secondsOf(g.timestamp), secondsOf(direct[i]->timestamp),
		            1.1e-6);
		for (auto k : {IMU_WX, IMU_WY, IMU_WZ})
			EXPECT_EQ(g.get(k), direct[i]->get(k)) << i;
		if ((firstIndex + i) % 2 == 0)
		{
			for (auto k : {IMU_X_ACC, IMU_Y_ACC, IMU_Z_ACC})
				EXPECT_NEAR(g.get(k), direct[i]->get(k), 1e-12) << i;
		}
		EXPECT_FALSE(g.has(IMU_MAG_X));
	}

	// the extrinsics round trip: the camera (the colour's, at the depth's
	// place here) to the IMU is the sample's R_IC and lever arm
	ASSERT_TRUE(sum.depthToColour);
	expectTransformNear(*sum.depthToColour, bag::RigidTransform(), 1e-12);
	ASSERT_TRUE(sum.cameraToImu);
	expectTransformNear(*sum.cameraToImu, spec.imuTf, 1e-9);
	EXPECT_TRUE(contains(sum.cameraToImuFrom, "Gyro_0/tf/0"));
	ASSERT_EQ(sum.calibrationFile, d + "/sdk_gt/calibration.ini");
	mrpt::config::CConfigFile cal(sum.calibrationFile);
	sensors::CalibrationParams c;
	c.loadFromConfigFile(cal, "calibration", true);
	sensors::CameraParams cam;
	cam.loadFromConfigFile(cal);
	for (int i = 0; i < 9; i++)
		EXPECT_NEAR(c.R_IC(i / 3, i % 3), spec.imuTf.R[i], 1e-8) << i;
	EXPECT_EQ(c.time_offset_s, 0);
	EXPECT_TRUE(cam.given);
	EXPECT_DOUBLE_EQ(cam.fx, s.frames[0]->cameraParams.fx());
	EXPECT_EQ(cam.width, 320);

	// found by --layout auto: the same rawlog, byte for byte
	const auto a = import(d + "/sdk.bag", d + "/auto.rawlog");
	EXPECT_EQ(a.layout, bag::BagLayout::RsSdk);
	EXPECT_EQ(fileText(d + "/auto.rawlog"), fileText(d + "/sdk.rawlog"));

	// and the realsense-ros recording of the same frames (16UC1 mm, accel
	// and gyro topics at the same rates) gives the same rawlog
	BagSpec rs;
	rs.splitImu = true;
	writeBag(d + "/rs.bag", rs, sample().frames, sample().imu);
	import(d + "/rs.bag", d + "/rs.rawlog");
	EXPECT_EQ(fileText(d + "/rs.rawlog"), fileText(d + "/sdk.rawlog"));
}

TEST(RsSdkImport, TheDepthIsRegisteredToTheColourCameraWithTheExtrinsics)
{
	const auto d = test::freshTmpDir("bims_rs_sdk", "register");
	RsSdkSpec spec;
	spec.frames = 3;
	spec.colourScale = 2;  // a 640x480 colour camera
	spec.colourTf = colourTf(2.0, 0.015);
	spec.imuTf = sampleImuTf();
	writeRsSdkBag(d + "/sdk.bag", spec, sample().frames, sample().imu);
	const auto sum = import(d + "/sdk.bag", d + "/sdk.rawlog");
	ASSERT_TRUE(sum.depthToColour);
	expectTransformNear(*sum.depthToColour, spec.colourTf, 1e-9);
	// the IMU relative to the colour camera: imu o colour^-1
	const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> Rc(
	    spec.colourTf.R),
	    Ri(spec.imuTf.R), Rgot(sum.cameraToImu->R);
	EXPECT_LT((Rgot - Ri * Rc.transpose()).norm(), 1e-9);
	EXPECT_EQ(sum.width, 640);
	EXPECT_EQ(sum.height, 480);

	const Sample got = readRawlog(d + "/sdk.rawlog");
	ASSERT_EQ(got.frames.size(), 3u);
	const auto& dc = sample().frames[0]->cameraParams;
	const Eigen::Vector3d t(spec.colourTf.t[0], spec.colourTf.t[1],
	                        spec.colourTf.t[2]);
	for (size_t k = 0; k < 3; k++)
	{
		const auto& f = *got.frames[k];
		const auto& src = *sample().frames[k];
		const auto& cc = f.cameraParams;
		EXPECT_DOUBLE_EQ(cc.fx(), 2 * dc.fx());
		EXPECT_DOUBLE_EQ(cc.cx(), (dc.cx() + 0.5) * 2 - 0.5);
		// each registered reading, taken back to the depth camera, is
		// the sample's reading there (within a pixel: the pixel squares)
		size_t readings = 0, good = 0, sourceReadings = 0;
		for (int v = 0; v < src.rangeImage.rows(); v++)
			for (int u = 0; u < src.rangeImage.cols(); u++)
				sourceReadings += src.rangeImage(v, u) != 0;
		for (int v = 0; v < f.rangeImage.rows(); v++)
			for (int u = 0; u < f.rangeImage.cols(); u++)
			{
				if (f.rangeImage(v, u) == 0) continue;
				readings++;
				const double z = f.rangeImage(v, u) * 0.001;
				const Eigen::Vector3d pc((u - cc.cx()) / cc.fx() * z,
				                         (v - cc.cy()) / cc.fy() * z, z);
				const Eigen::Vector3d pd = Rc.transpose() * (pc - t);
				const double ud = dc.fx() * pd.x() / pd.z() + dc.cx(),
				             vd = dc.fy() * pd.y() / pd.z() + dc.cy();
				double best = 1e9;
				for (int dv = -1; dv <= 1; dv++)
					for (int du = -1; du <= 1; du++)
					{
						const int x = static_cast<int>(std::lround(ud)) + du,
						          y = static_cast<int>(std::lround(vd)) + dv;
						if (x < 0 || y < 0 || x >= src.rangeImage.cols() ||
						    y >= src.rangeImage.rows() ||
						    src.rangeImage(y, x) == 0)
							continue;
						best = std::min(
						    best,
						    std::abs(src.rangeImage(y, x) * 0.001 - pd.z()));
					}
				good += best < 0.002 + 0.002 * z;
			}
		EXPECT_GT(readings, 3 * sourceReadings) << k;
		EXPECT_GT(good, readings * 995 / 1000)
		    << k << ": " << good << " of " << readings;
	}
}

TEST(RsSdkImport, StreamsAreFoundByNameAndTheUnitsWhereverTheRecordingKeepsThem)
{
	const auto d = test::freshTmpDir("bims_rs_sdk", "names");
	// another model's numbering, the depth units in the images only (the
	// newer recorder's), the old option name absent
	RsSdkSpec spec;
	spec.frames = 6;
	spec.depthSensor = 1;
	spec.colourSensor = 0;
	spec.motionSensor = 3;
	spec.unitsOption.clear();
	spec.units = spec.imageUnits = 0.0001f;
	spec.depthEncoding = "16UC1";
	writeRsSdkBag(d + "/a.bag", spec, sample().frames, sample().imu);
	auto sum = import(d + "/a.bag", d + "/a.rawlog");
	EXPECT_EQ(sum.layout, bag::BagLayout::RsSdk);
	EXPECT_EQ(sum.topics.depth, "/device_0/sensor_1/Depth_0/image/data");
	EXPECT_EQ(sum.topics.accel, "/device_0/sensor_3/Accel_0/imu/data");
	EXPECT_FLOAT_EQ(static_cast<float>(sum.depthUnits), 0.0001f);
	EXPECT_TRUE(contains(sum.depthUnitsFrom, "own depth_units"))
	    << sum.depthUnitsFrom;
	// 0.1 mm units: the sample's millimetres again
	expectTheSampleFrames(readRawlog(d + "/a.rawlog"), 6);

	// the option and the images' units both: they must agree
	spec.unitsOption = "Depth Units";
	spec.units = 0.001f;
	spec.imageUnits = 0.0001f;
	writeRsSdkBag(d + "/b.bag", spec, sample().frames, sample().imu);
	auto e = errorOf([&] { import(d + "/b.bag", d + "/b.rawlog"); });
	EXPECT_TRUE(contains(e, d + "/b.bag")) << e;
	EXPECT_TRUE(contains(e,
	                     "/device_0/sensor_1/Depth_0/image/data, "
	                     "message #1"))
	    << e;
	EXPECT_TRUE(contains(e, "own depth units 0.0001 m differ")) << e;
	EXPECT_FALSE(fs::exists(d + "/b.rawlog"));

	// neither: an error, unless --depth-units gives them
	spec.unitsOption.clear();
	spec.imageUnits = 0;
	writeRsSdkBag(d + "/c.bag", spec, sample().frames, sample().imu);
	e = errorOf([&] { import(d + "/c.bag", d + "/c.rawlog"); });
	EXPECT_TRUE(contains(e, d + "/c.bag: no depth units")) << e;
	EXPECT_TRUE(contains(e, "--depth-units")) << e;
	bag::BagImportParams p;
	p.depthUnits = 0.001;
	sum = import(d + "/c.bag", d + "/c.rawlog", p);
	EXPECT_TRUE(contains(sum.depthUnitsFrom, "depth_units"))
	    << sum.depthUnitsFrom;
	expectTheSampleFrames(readRawlog(d + "/c.rawlog"), 6);

	// colour_topic = none: the depth alone, in the depth camera
	p.topics.colour = "none";
	sum = import(d + "/c.bag", d + "/depth.rawlog", p);
	EXPECT_EQ(sum.cameraFrom,
	          "CameraInfo /device_0/sensor_1/Depth_0/info/camera_info");
	EXPECT_FALSE(sum.depthToColour);
	const auto got = readRawlog(d + "/depth.rawlog");
	ASSERT_EQ(got.frames.size(), 6u);
	EXPECT_FALSE(got.frames[0]->hasIntensityImage);
	EXPECT_TRUE((got.frames[5]->rangeImage.array() ==
	             sample().frames[5]->rangeImage.array())
	                .all());
}

TEST(RsSdkImport, BadRecordingsAreClearErrorsNamingBagTopicAndMessage)
{
	const auto d = test::freshTmpDir("bims_rs_sdk", "bad");
	auto importOf = [&](const RsSdkSpec& spec, const std::string& name)
	{
		writeRsSdkBag(d + "/" + name + ".bag", spec, sample().frames,
		              sample().imu);
		return errorOf(
		    [&]
		    {
			    bag::BagImportParams p;
			    p.layout = bag::BagLayout::RsSdk;
			    import(d + "/" + name + ".bag", d + "/" + name + ".rawlog", p);
		    });
	};
	RsSdkSpec base;
	base.frames = 4;

	RsSdkSpec s = base;
	s.depthInfo = false;
	auto e = importOf(s, "noDepthInfo");
	EXPECT_TRUE(contains(e, d + "/noDepthInfo.bag: the depth stream")) << e;
	EXPECT_TRUE(contains(e, "/device_0/sensor_0/Depth_0/info/camera_info"))
	    << e;

	s = base;
	s.colourInfo = false;
	e = importOf(s, "noColourInfo");
	EXPECT_TRUE(contains(e,
	                     "no CameraInfo topic "
	                     "/device_0/sensor_1/Color_0/info/camera_info"))
	    << e;

	s = base;
	s.nanColourTf = true;
	e = importOf(s, "nanTf");
	EXPECT_TRUE(contains(e, d + "/nanTf.bag: topic "
	                            "/device_0/sensor_1/Color_0/tf/0, message #1"))
	    << e;
	EXPECT_TRUE(contains(e, "not finite")) << e;
	EXPECT_FALSE(fs::exists(d + "/nanTf.rawlog"));

	s = base;
	s.tf = false;
	e = importOf(s, "noTf");
	EXPECT_TRUE(contains(e, "no extrinsics between the depth stream")) << e;

	s = base;
	s.depthEncoding = "32FC1";
	e = importOf(s, "float");
	EXPECT_TRUE(contains(e,
	                     "/device_0/sensor_0/Depth_0/image/data, "
	                     "message #1"))
	    << e;
	EXPECT_TRUE(contains(e,
	                     "encoding '32FC1' is not supported (16UC1, "
	                     "mono16)"))
	    << e;

	// an accelerometer without its gyro: imported, said in a warning, the
	// samples accelerometer-only
	s = base;
	s.gyro = false;
	EXPECT_EQ(importOf(s, "noGyro"), "(no error)");
	bag::BagImportParams p;
	const auto sum = import(d + "/noGyro.bag", d + "/noGyro.rawlog", p);
	bool warned = false;
	for (const auto& n : sum.notes)
		warned |= contains(n,
		                   "accelerometer stream "
		                   "/device_0/sensor_2/Accel_0/imu/data has no "
		                   "gyro stream");
	EXPECT_TRUE(warned);
	const auto got = readRawlog(d + "/noGyro.rawlog");
	ASSERT_FALSE(got.imu.empty());
	EXPECT_EQ(got.imu[0]->sensorLabel, "ACCEL");
	EXPECT_FALSE(got.imu[0]->has(mrpt::obs::IMU_WX));
}

TEST(RsSdkImport, TheProgramImportsAnSdkRecordingAndBimsRunsTheResult)
{
	const auto d = test::freshTmpDir("bims_rs_sdk", "app");
	RsSdkSpec spec;
	spec.frames = 12;
	spec.imuTf = sampleImuTf();
	writeRsSdkBag(d + "/rec.bag", spec, sample().frames, sample().imu);
	auto r = test::runCommand("'" + kImport + "' '" + d + "/rec.bag' --topics");
	EXPECT_EQ(r.code, 0) << r.out;
	EXPECT_TRUE(contains(r.out, "/device_0/sensor_0/option/Depth Units/value"))
	    << r.out;
	r = test::runCommand("'" + kImport + "' '" + d +
	                     "/rec.bag' --layout rs-sdk -q -o '" + d +
	                     "/rec.rawlog'");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_TRUE(contains(r.out,
	                     "12 RGB-D frames of 320x240 (depth mono16 "
	                     "from /device_0/sensor_0/Depth_0/image/data"))
	    << r.out;
	EXPECT_TRUE(contains(r.out, "layout: rs-sdk")) << r.out;
	EXPECT_TRUE(contains(r.out,
	                     "depth units 0.001 m from the Depth Units "
	                     "option"))
	    << r.out;
	EXPECT_TRUE(contains(r.out, "IMU extrinsics from tf")) << r.out;
	EXPECT_TRUE(contains(r.out, "merged at the gyro's stamps")) << r.out;
	EXPECT_TRUE(fs::exists(d + "/rec_gt/calibration.ini")) << r.out;

	// bims-run on it (the default experiment's R_IC is the sample's, which
	// the recording's tf carried)
	r = test::runCommand("'" + kRun + "' '" + test::kDefaultConfig + "' '" + d +
	                     "/rec.rawlog' -o '" + d + "/run' -q");
	EXPECT_EQ(r.code, 0) << r.out;
	EXPECT_TRUE(fs::exists(d + "/run/masks/000011.png")) << r.out;

	// --depth-units replaces the recording's; out of range: a usage error
	r = test::runCommand("'" + kImport + "' '" + d +
	                     "/rec.bag' --depth-units 0.002 -q -o '" + d +
	                     "/two.rawlog'");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_TRUE(contains(r.out, "depth units 0.002 m from")) << r.out;
	r = test::runCommand("'" + kImport + "' '" + d +
	                     "/rec.bag' --depth-units 5 -q -o '" + d +
	                     "/bad.rawlog'");
	EXPECT_NE(r.code, 0) << r.out;
	EXPECT_TRUE(contains(r.out, "--depth-units 5")) << r.out;
}

}  // namespace
