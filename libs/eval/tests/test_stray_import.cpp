// bims-import-stray (stray_import.h; its run: bims/apps/stray_import_run.h): a
// Stray Scanner capture made by the test itself, imported and checked
// convention by convention; bad input; the shared real capture (skipped without
// it); the built program's command line.
#include <bims/common/config.h>
#include <bims/eval/stray_import.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims_test/data.h>
#include <bims_test/run_command.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/poses/CPose3DQuat.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>

namespace
{
namespace fs = std::filesystem;
namespace ev = bims::eval;
using mrpt::obs::CObservation3DRangeScan;
using mrpt::obs::CObservationIMU;

// The synthetic capture: 6 frames of 32x24 depth, a 128x96 video (4x the
// depth grid), ARKit-like stamps.
constexpr int kFrames = 6, kW = 32, kH = 24, kVideoW = 128, kVideoH = 96;
constexpr double kT0 = 248630.569939083, kDt = 0.016668333;

/** Frame k's stamp as odometry.csv holds it (9 decimals). */
double frameTime(int k)
{
	char b[64];
	std::snprintf(b, sizeof(b), "%.9f", kT0 + kDt * k);
	return std::stod(b);
}

/** Depth in mm of frame k at (u, v); some pixels 0 (no reading). */
uint16_t depthMm(int k, int u, int v)
{
	if ((u + v + k) % 7 == 0) return 0;
	return static_cast<uint16_t>(500 + 10 * k + u + 40 * v);
}
/** ARKit's confidence 0/1/2 of frame k at (u, v). */
uint8_t confidence(int k, int u, int v)
{
	return static_cast<uint8_t>((u + 2 * v + k) % 3);
}
/** Frame k's flat colour (BGR), far apart from the others: frame 0 pure
 * red. */
cv::Vec3b colour(int k)
{
	static const cv::Vec3b c[kFrames] = {{0, 0, 255},   {0, 255, 0},
	                                     {255, 0, 0},   {0, 255, 255},
	                                     {255, 0, 255}, {255, 255, 0}};
	return c[k];
}
/** Frame k's pose: rows 0 and 1 at translation exactly 0 (ARKit
 * initialising). */
void pose(int k, double p[3], double q[4])
{
	p[0] = k < 2 ? 0 : 0.1 * k;
	p[1] = k < 2 ? 0 : -0.05 * k;
	p[2] = k < 2 ? 0 : 0.02 * k + 0.003;
	Eigen::Vector3d axis(0.3, -0.8, 0.5);
	axis.normalize();
	const double h = 0.5 * (1.2 + 0.1 * k);
	q[0] = std::sin(h) * axis.x();
	q[1] = std::sin(h) * axis.y();
	q[2] = std::sin(h) * axis.z();
	q[3] = std::cos(h);
}

/** imu.csv's rows: 3 before the first frame, one at frame 2's stamp
 * exactly, 3 after the last frame. */
struct ImuRow
{
	double t, a[3], w[3];
};
std::vector<ImuRow> imuRows()
{
	std::vector<ImuRow> rows;
	std::vector<double> ts;
	for (int i = 3; i >= 1; i--) ts.push_back(kT0 - 0.01 * i);
	for (double t = kT0 + 0.005; t < frameTime(kFrames - 1); t += 0.01)
		ts.push_back(t);
	ts.push_back(frameTime(2));
	for (int i = 1; i <= 3; i++)
		ts.push_back(frameTime(kFrames - 1) + 0.004 * i);
	std::sort(ts.begin(), ts.end());
	for (size_t i = 0; i < ts.size(); i++)
	{
		const double x = static_cast<double>(i);
		// as the file stores them: round-trip through the text
		char b[64];
		std::snprintf(b, sizeof(b), "%.9f", ts[i]);
		rows.push_back({std::stod(b),
		                {0.1 + x, -9.8 + 0.01 * x, 0.5 - 0.02 * x},
		                {0.001 * x, -0.002 * x, 0.1 + 0.003 * x}});
	}
	return rows;
}

struct CaptureSpec
{
	bool video = true;
	int videoFrames = kFrames;
	int videoW = kVideoW, videoH = kVideoH;
	bool confidence = true;
	bool imu = true;
};

/** Writes the capture into TMP/bims_test_stray/NAME; returns the folder. */
std::string makeCapture(const std::string& name, const CaptureSpec& spec = {})
{
	const auto d = bims::test::freshTmpDir("bims_test_stray", name);
	fs::create_directories(d + "/depth");
	if (spec.confidence) fs::create_directories(d + "/confidence");
	std::ofstream odo(d + "/odometry.csv");
	odo << "timestamp, frame, x, y, z, qx, qy, qz, qw\n";
	for (int k = 0; k < kFrames; k++)
	{
		cv::Mat depth(kH, kW, CV_16UC1), conf(kH, kW, CV_8UC1);
		for (int v = 0; v < kH; v++)
			for (int u = 0; u < kW; u++)
			{
				depth.at<uint16_t>(v, u) = depthMm(k, u, v);
				conf.at<uint8_t>(v, u) = confidence(k, u, v);
			}
		char n[16];
		std::snprintf(n, sizeof(n), "%06d", k);
		EXPECT_TRUE(cv::imwrite(d + "/depth/" + n + ".png", depth));
		if (spec.confidence)
		{
			EXPECT_TRUE(cv::imwrite(d + "/confidence/" + n + ".png", conf));
		}
		double p[3], q[4];
		pose(k, p, q);
		char row[256];
		std::snprintf(row, sizeof(row),
		              "%.9f, %s, %.9g, %.9g, %.9g, %.9f, %.9f, %.9f, %.9f\n",
		              frameTime(k), n, p[0], p[1], p[2], q[0], q[1], q[2],
		              q[3]);
		odo << row;
	}
	// no newline after the last row, as Stray writes it
	std::ofstream(d + "/camera_matrix.csv")
	    << "100.0, 0.0, 64.5\n0.0, 96.0, 47.25\n0.0, 0.0, 1.0";
	if (spec.imu)
	{
		std::ofstream imu(d + "/imu.csv");
		imu << "timestamp, a_x, a_y, a_z, alpha_x, alpha_y, alpha_z\n";
		for (const auto& r : imuRows())
		{
			char row[256];
			std::snprintf(row, sizeof(row),
			              "%.9f, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g\n",
			              r.t, r.a[0], r.a[1], r.a[2], r.w[0], r.w[1], r.w[2]);
			imu << row;
		}
	}
	if (spec.video)
	{
		cv::VideoWriter vw(d + "/rgb.mp4",
		                   cv::VideoWriter::fourcc('m', 'p', '4', 'v'), 60.0,
		                   cv::Size(spec.videoW, spec.videoH));
		// no skip: the pairing of video and depth frames is the test
		EXPECT_TRUE(vw.isOpened()) << "OpenCV cannot write mp4v";
		for (int k = 0; k < spec.videoFrames; k++)
			vw.write(cv::Mat(
			    spec.videoH, spec.videoW, CV_8UC3,
			    cv::Scalar(colour(k % kFrames)[0], colour(k % kFrames)[1],
			               colour(k % kFrames)[2])));
	}
	return d;
}

ev::StrayImportOptions quiet()
{
	ev::StrayImportOptions o;
	return o;
}

/** The message of the error importStray throws ("" if none). */
std::string importError(const std::string& folder,
                        const ev::StrayImportParams& params = {})
{
	fs::remove(folder + "/../out.rawlog");
	try
	{
		ev::importStray(folder, folder + "/../out.rawlog", params, quiet());
	}
	catch (const std::exception& e)
	{
		return e.what();
	}
	return "";
}

std::vector<mrpt::obs::CObservation::Ptr> readAll(const std::string& path)
{
	std::vector<mrpt::obs::CObservation::Ptr> v;
	bims::RawlogReader r(path);
	while (auto o = r.next()) v.push_back(o);
	return v;
}

double stampOf(const mrpt::obs::CObservation& o)
{
	return mrpt::Clock::toDouble(o.timestamp);
}

size_t count(const std::string& text, const std::string& what)
{
	size_t n = 0;
	for (auto p = text.find(what); p != std::string::npos;
	     p = text.find(what, p + 1))
		n++;
	return n;
}
}  // namespace

TEST(ImportStray, SyntheticCaptureEveryConvention)
{
	const auto d = makeCapture("all");
	const std::string out = d + "_out/all.rawlog";
	fs::create_directories(d + "_out");
	ev::StrayImportParams high;  // high confidence only (1 below)
	high.min_confidence = 2;
	const auto sum = ev::importStray(d, out, high, quiet());
	EXPECT_FALSE(fs::exists(out + ".partial"));
	const auto obs = readAll(out);
	const auto imu = imuRows();

	// what must be there, in this order: IMU up to the last frame's stamp
	// (those before the first frame too), IMU first at equal stamps
	std::vector<std::pair<double, int>> expect;  // (t, 0 IMU / 1 frame)
	size_t imuKept = 0, imuBefore = 0;
	for (const auto& r : imu)
		if (r.t <= frameTime(kFrames - 1))
		{
			expect.push_back({r.t, 0});
			imuKept++;
			imuBefore += r.t < kT0;
		}
	for (int k = 0; k < kFrames; k++) expect.push_back({frameTime(k), 1});
	std::stable_sort(expect.begin(), expect.end());
	ASSERT_EQ(imuBefore, 3u);
	ASSERT_EQ(imuKept + 3, imu.size());  // the 3 after the last frame go
	ASSERT_EQ(obs.size(), expect.size());
	EXPECT_EQ(sum.frames, size_t(kFrames));
	EXPECT_EQ(sum.imu, imuKept);
	EXPECT_EQ(sum.imuBeforeFirst, 3u);
	EXPECT_TRUE(sum.colour);
	EXPECT_EQ(sum.videoWidth, kVideoW);
	EXPECT_EQ(sum.width, kW);
	EXPECT_EQ(sum.height, kH);

	size_t k = 0, i = 0, readings = 0, dropped = 0;
	bool sawEqualStamps = false;
	for (size_t n = 0; n < obs.size(); n++)
	{
		const double t = stampOf(*obs[n]);
		EXPECT_NEAR(t, expect[n].first, 1e-6) << n;
		if (expect[n].second == 0)
		{
			const auto m = std::dynamic_pointer_cast<CObservationIMU>(obs[n]);
			ASSERT_TRUE(m) << "observation " << n << " should be IMU";
			// i-th row of imu.csv
			const auto& r = imu[i++];
			EXPECT_NEAR(t, r.t, 1e-6);
			EXPECT_EQ(m->sensorLabel, "IMU");
			// Apple's accelerometer points down at rest: specific force -a
			EXPECT_DOUBLE_EQ(m->get(mrpt::obs::IMU_X_ACC), -r.a[0]);
			EXPECT_DOUBLE_EQ(m->get(mrpt::obs::IMU_Y_ACC), -r.a[1]);
			EXPECT_DOUBLE_EQ(m->get(mrpt::obs::IMU_Z_ACC), -r.a[2]);
			EXPECT_DOUBLE_EQ(m->get(mrpt::obs::IMU_WX), r.w[0]);
			EXPECT_DOUBLE_EQ(m->get(mrpt::obs::IMU_WY), r.w[1]);
			EXPECT_DOUBLE_EQ(m->get(mrpt::obs::IMU_WZ), r.w[2]);
			// those six only: no magnetometer, no orientation
			size_t present = 0;
			for (size_t f = 0; f < m->dataIsPresent.size(); f++)
				present += m->dataIsPresent[f];
			EXPECT_EQ(present, 6u);
			if (n + 1 < obs.size() && expect[n + 1].second == 1 &&
			    expect[n + 1].first == r.t)
				sawEqualStamps = true;
			continue;
		}
		const auto s =
		    std::dynamic_pointer_cast<CObservation3DRangeScan>(obs[n]);
		ASSERT_TRUE(s) << "observation " << n << " should be a 3D scan";
		SCOPED_TRACE("frame " + std::to_string(k));
		EXPECT_NEAR(t, frameTime(static_cast<int>(k)), 1e-6);
		EXPECT_EQ(s->sensorLabel, "RGBD");
		EXPECT_TRUE(s->range_is_depth);
		EXPECT_FLOAT_EQ(s->rangeUnits, 0.001f);
		ASSERT_EQ(s->rangeImage.cols(), kW);
		ASSERT_EQ(s->rangeImage.rows(), kH);
		// intrinsics of 128x96 scaled to 32x24 (x 1/4)
		EXPECT_DOUBLE_EQ(s->cameraParams.fx(), 100.0 * 32 / 128);
		EXPECT_DOUBLE_EQ(s->cameraParams.fy(), 96.0 * 24 / 96);
		EXPECT_DOUBLE_EQ(s->cameraParams.cx(), 64.5 * 32 / 128);
		EXPECT_DOUBLE_EQ(s->cameraParams.cy(), 47.25 * 24 / 96);
		EXPECT_EQ(s->cameraParams.ncols, 32u);
		EXPECT_EQ(s->cameraParams.distortion, mrpt::img::DistortionModel::none);
		EXPECT_DOUBLE_EQ(s->cameraParamsIntensity.fx(), 25.0);
		// depth in mm exactly; confidence below 2 dropped
		const int kk = static_cast<int>(k);
		for (int v = 0; v < kH; v++)
			for (int u = 0; u < kW; u++)
			{
				const uint16_t raw = depthMm(kk, u, v);
				readings += raw > 0;
				const bool drop = raw > 0 && confidence(kk, u, v) < 2;
				dropped += drop;
				ASSERT_EQ(s->rangeImage(v, u), drop ? 0 : raw)
				    << "pixel " << u << "," << v;
			}
		// metres at a few pixels: (5,3) has confidence 2 in frame 0
		if (k == 0)
		{
			ASSERT_EQ(confidence(0, 5, 3), 2);
			EXPECT_NEAR(s->rangeImage(3, 5) * s->rangeUnits, 0.625, 1e-6);
			EXPECT_EQ(s->rangeImage(0, 0), 0);  // no reading
			ASSERT_EQ(confidence(0, 1, 0), 1);
			EXPECT_EQ(s->rangeImage(0, 1), 0);  // confidence 1: dropped
		}
		// colour: frame k's, BGR, the depth grid's size
		ASSERT_TRUE(s->hasIntensityImage);
		EXPECT_EQ(s->intensityImageChannel,
		          CObservation3DRangeScan::CH_VISIBLE);
		EXPECT_TRUE(
		    s->relativePoseIntensityWRTDepth.asTPose() ==
		    mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2).asTPose());
		const cv::Mat img =
		    s->intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY);
		ASSERT_EQ(img.type(), CV_8UC3);
		ASSERT_EQ(img.cols, kW);
		ASSERT_EQ(img.rows, kH);
		const cv::Scalar mean = cv::mean(img);
		for (int c = 0; c < 3; c++)
			EXPECT_NEAR(mean[c], colour(kk)[c], 30) << "channel " << c;
		if (k == 0)
		{
			// pure red: the third byte of BGR
			const cv::Vec3b px = img.at<cv::Vec3b>(12, 16);
			EXPECT_GT(px[2], 200);
			EXPECT_LT(px[1], 50);
			EXPECT_LT(px[0], 50);
		}
		k++;
	}
	EXPECT_EQ(k, size_t(kFrames));
	EXPECT_EQ(i, imuKept);
	EXPECT_TRUE(sawEqualStamps);
	EXPECT_EQ(sum.readings, readings);
	EXPECT_EQ(sum.dropped, dropped);
	EXPECT_GT(dropped, readings / 2);  // 2 of 3 confidence values

	// the reference: ARKit's poses from the first with a position
	EXPECT_EQ(sum.referencePath, d + "_out/all_arkit_reference.txt");
	EXPECT_EQ(sum.referenceLeftOut, 2u);
	EXPECT_EQ(sum.referencePoses, size_t(kFrames - 2));
	std::ifstream rf(sum.referencePath);
	std::string header;
	std::getline(rf, header);
	EXPECT_NE(header.find("NOT ground truth"), std::string::npos) << header;
	EXPECT_NE(header.find("y up"), std::string::npos) << header;
	const auto ref = bims::loadTumTrajectory(sum.referencePath);
	ASSERT_EQ(ref.size(), size_t(kFrames - 2));
	for (int j = 2; j < kFrames; j++)
	{
		const auto& r = ref[j - 2];
		double p[3], q[4];
		pose(j, p, q);
		EXPECT_NEAR(r.t, frameTime(j), 1e-6);
		const mrpt::poses::CPose3DQuat pq(r.T_WC);
		EXPECT_NEAR(pq.x(), p[0], 1e-8);
		EXPECT_NEAR(pq.y(), p[1], 1e-8);
		EXPECT_NEAR(pq.z(), p[2], 1e-8);
		// the same rotation: q or -q
		const double dot = pq.quat().x() * q[0] + pq.quat().y() * q[1] +
		                   pq.quat().z() * q[2] + pq.quat().r() * q[3];
		EXPECT_NEAR(std::abs(dot), 1.0, 1e-8) << j;
	}

	// min_confidence 0 keeps every reading, 1 those of confidence 1 and 2
	for (int minConf : {0, 1})
	{
		ev::StrayImportParams p;
		p.min_confidence = minConf;
		const std::string o2 =
		    d + "_out/c" + std::to_string(minConf) + ".rawlog";
		const auto s2 = ev::importStray(d, o2, p, quiet());
		size_t kept = 0, expectKept = 0, f = 0;
		for (const auto& o : readAll(o2))
			if (auto s = std::dynamic_pointer_cast<CObservation3DRangeScan>(o))
			{
				const int kk = static_cast<int>(f++);
				for (int v = 0; v < kH; v++)
					for (int u = 0; u < kW; u++)
					{
						const uint16_t raw = depthMm(kk, u, v);
						const bool keep =
						    raw > 0 && confidence(kk, u, v) >= minConf;
						expectKept += keep;
						kept += s->rangeImage(v, u) > 0;
						EXPECT_EQ(s->rangeImage(v, u), keep ? raw : 0);
					}
			}
		EXPECT_EQ(kept, expectKept);
		EXPECT_EQ(s2.readings - s2.dropped, expectKept);
		if (minConf == 0)
		{
			EXPECT_EQ(kept, readings);
		}
	}

	// --max-frames: the first 3 frames, IMU up to the third's stamp, the
	// reference from the third on
	ev::StrayImportOptions three = quiet();
	three.maxFrames = 3;
	const auto s3 = ev::importStray(d, d + "_out/three.rawlog.gz", {}, three);
	EXPECT_EQ(s3.frames, 3u);
	EXPECT_EQ(s3.referencePoses, 1u);
	EXPECT_EQ(s3.referencePath, d + "_out/three_arkit_reference.txt");
	const auto o3 = readAll(d + "_out/three.rawlog.gz");
	ASSERT_FALSE(o3.empty());
	EXPECT_TRUE(std::dynamic_pointer_cast<CObservation3DRangeScan>(o3.back()));
	EXPECT_NEAR(stampOf(*o3.back()), frameTime(2), 1e-6);
}

TEST(ImportStray, ProgressIsReportedThroughTheCallbackUpToTheTotal)
{
	CaptureSpec spec;
	spec.video = false;
	const auto d = makeCapture("progress", spec);
	std::vector<bims::Progress> seen;
	ev::StrayImportOptions o;
	o.progress = [&](const bims::Progress& p) { seen.push_back(p); };
	const auto sum = ev::importStray(d, d + "/../progress.rawlog", {}, o);
	ASSERT_GE(seen.size(), 3u);
	// {0, total} at the start, each frame done, the last one finished
	EXPECT_EQ(seen.front().done, 0u);
	for (const auto& p : seen) EXPECT_EQ(p.total, sum.frames);
	for (size_t k = 1; k < seen.size(); ++k)
		EXPECT_GE(seen[k].done, seen[k - 1].done);
	EXPECT_EQ(seen.back().done, sum.frames);
	EXPECT_TRUE(seen.back().finished);
	EXPECT_EQ(std::count_if(seen.begin(), seen.end(),
	                        [](const bims::Progress& p) { return p.finished; }),
	          1);
}

TEST(ImportStray, WithoutVideoScansHaveNoColourAndItIsSaidOnce)
{
	CaptureSpec spec;
	spec.video = false;
	const auto d = makeCapture("novideo", spec);
	testing::internal::CaptureStderr();
	const auto sum = ev::importStray(d, d + "/../novideo.rawlog", {}, quiet());
	const std::string err = testing::internal::GetCapturedStderr();
	EXPECT_EQ(count(err, "rgb.mp4: not found"), 1u) << err;
	EXPECT_EQ(count(err, "the scans have no colour image"), 1u) << err;
	EXPECT_FALSE(sum.colour);
	size_t scans = 0;
	for (const auto& o : readAll(d + "/../novideo.rawlog"))
		if (auto s = std::dynamic_pointer_cast<CObservation3DRangeScan>(o))
		{
			scans++;
			EXPECT_FALSE(s->hasIntensityImage);
			// camera_matrix.csv's colour stream: [import_stray]
			// colour_width x colour_height (default 1920x1440)
			EXPECT_DOUBLE_EQ(s->cameraParams.fx(), 100.0 * 32 / 1920);
			EXPECT_DOUBLE_EQ(s->cameraParams.cy(), 47.25 * 24 / 1440);
		}
	EXPECT_EQ(scans, size_t(kFrames));
	// the colour size from the .ini
	mrpt::config::CConfigFileMemory ini(
	    "[import_stray]\ncolour_width = 128\ncolour_height = 96\n");
	ev::StrayImportParams p;
	p.loadFromConfigFile(ini);
	testing::internal::CaptureStderr();
	const auto s2 = ev::importStray(d, d + "/../novideo2.rawlog", p, quiet());
	testing::internal::GetCapturedStderr();
	EXPECT_DOUBLE_EQ(s2.camera.fx(), 25.0);
	EXPECT_DOUBLE_EQ(s2.camera.cx(), 64.5 / 4);
}

TEST(ImportStray, WithoutConfidenceEveryReadingIsKeptAndItIsSaidOnce)
{
	CaptureSpec spec;
	spec.confidence = false;
	spec.imu = false;
	const auto d = makeCapture("noconf", spec);
	testing::internal::CaptureStderr();
	const auto sum = ev::importStray(d, d + "/../noconf.rawlog", {}, quiet());
	const std::string err = testing::internal::GetCapturedStderr();
	EXPECT_EQ(count(err, "confidence: not found"), 1u) << err;
	EXPECT_EQ(count(err, "imu.csv: not found"), 1u) << err;
	EXPECT_FALSE(sum.confidence);
	EXPECT_EQ(sum.dropped, 0u);
	EXPECT_EQ(sum.imu, 0u);
	int k = 0;
	for (const auto& o : readAll(d + "/../noconf.rawlog"))
	{
		const auto s = std::dynamic_pointer_cast<CObservation3DRangeScan>(o);
		ASSERT_TRUE(s);  // no IMU at all
		for (int v = 0; v < kH; v++)
			for (int u = 0; u < kW; u++)
				ASSERT_EQ(s->rangeImage(v, u), depthMm(k, u, v));
		k++;
	}
	EXPECT_EQ(k, kFrames);
}

TEST(ImportStray, BadInputIsAClearErrorNamingTheFile)
{
	// the video: fewer frames, more frames, another aspect ratio
	{
		CaptureSpec s;
		s.videoFrames = kFrames - 1;
		const auto d = makeCapture("short_video", s);
		const auto e = importError(d);
		EXPECT_NE(e.find(d + "/rgb.mp4: 5 video frames, but the capture has 6 "
		                     "depth frames"),
		          std::string::npos)
		    << e;
		EXPECT_FALSE(fs::exists(d + "/../out.rawlog"));
		s.videoFrames = kFrames + 1;
		const auto d2 = makeCapture("long_video", s);
		const auto e2 = importError(d2);
		EXPECT_NE(e2.find(d2 + "/rgb.mp4: 7 video frames, but the capture has "
		                       "6 depth frames"),
		          std::string::npos)
		    << e2;
		// --max-frames does not hide it: the count is the capture's
		ev::StrayImportOptions o = quiet();
		o.maxFrames = 2;
		EXPECT_THROW(ev::importStray(d2, d2 + "/../x.rawlog", {}, o),
		             std::runtime_error);
		// with a video, frame k must be row k: a capture whose last frame
		// is numbered 7 cannot be paired with video frame 5
		const auto d4 = makeCapture("renumbered");
		fs::rename(d4 + "/depth/000005.png", d4 + "/depth/000007.png");
		fs::rename(d4 + "/confidence/000005.png",
		           d4 + "/confidence/000007.png");
		{
			std::ifstream f(d4 + "/odometry.csv");
			std::stringstream text;
			text << f.rdbuf();
			std::string t = text.str();
			t.replace(t.find(", 000005,"), 9, ", 000007,");
			std::ofstream(d4 + "/odometry.csv") << t;
		}
		const auto e4 = importError(d4);
		EXPECT_NE(e4.find(d4 + "/odometry.csv:7: frame 7 is row 6: with "
		                       "rgb.mp4 the frames must be 0, 1, 2"),
		          std::string::npos)
		    << e4;
		CaptureSpec sq;
		sq.videoW = 96;
		const auto d3 = makeCapture("square_video", sq);
		const auto e3 = importError(d3);
		EXPECT_NE(e3.find(d3 + "/rgb.mp4: video frames are 96x96, not of the "
		                       "depth images' aspect ratio (32x24"),
		          std::string::npos)
		    << e3;
	}
	CaptureSpec noVideo;
	noVideo.video = false;
	testing::internal::CaptureStderr();  // the notes of no video
	// a CSV row: truncated, not a number, time not increasing
	for (const std::string file : {"imu.csv", "odometry.csv"})
	{
		const bool isImu = file == "imu.csv";
		const auto d = makeCapture("bad_" + file, noVideo);
		std::vector<std::string> lines;
		{
			std::ifstream f(d + "/" + file);
			for (std::string l; std::getline(f, l);) lines.push_back(l);
		}
		auto write = [&](size_t at, const std::string& text)
		{
			std::ofstream f(d + "/" + file);
			for (size_t j = 0; j < lines.size(); j++)
				f << (j == at ? text : lines[j]) << "\n";
		};
		// line 4 of the file (index 3)
		write(3, lines[3].substr(0, lines[3].find(',', 30)));
		auto e = importError(d);
		EXPECT_NE(e.find(d + "/" + file + ":4: expected " +
		                 (isImu ? "7" : "9") + " comma-separated values"),
		          std::string::npos)
		    << e;
		std::string bad = lines[3];
		bad.replace(bad.rfind(','), std::string::npos, ", 0.5x");
		write(3, bad);
		e = importError(d);
		EXPECT_NE(e.find(d + "/" + file + ":4: " + (isImu ? "alpha_z" : "qw") +
		                 " '0.5x' is not a finite number"),
		          std::string::npos)
		    << e;
		write(3, lines[2]);  // the stamp of line 3 again
		e = importError(d);
		EXPECT_NE(e.find(d + "/" + file + ":4: timestamp "), std::string::npos)
		    << e;
		EXPECT_NE(e.find("is not after the previous row's"), std::string::npos)
		    << e;
		write(3, "");
		std::ofstream(d + "/" + file, std::ios::app) << lines[2] << "\n";
		e = importError(d);  // backwards at the end
		EXPECT_NE(e.find(d + "/" + file + ":"), std::string::npos) << e;
		EXPECT_NE(e.find("time must increase"), std::string::npos) << e;
		EXPECT_FALSE(fs::exists(d + "/../out.rawlog"));
	}
	// odometry.csv and camera_matrix.csv missing, a camera matrix row bad
	{
		const auto d = makeCapture("no_odometry", noVideo);
		fs::remove(d + "/odometry.csv");
		EXPECT_NE(importError(d).find(d + "/odometry.csv: not found"),
		          std::string::npos);
		const auto d2 = makeCapture("no_matrix", noVideo);
		fs::remove(d2 + "/camera_matrix.csv");
		EXPECT_NE(importError(d2).find(d2 + "/camera_matrix.csv: cannot open"),
		          std::string::npos);
		std::ofstream(d2 + "/camera_matrix.csv")
		    << "100.0, 0.0, 64.5\n0.0, 96.0\n0.0, 0.0, 1.0";
		const auto e = importError(d2);
		EXPECT_NE(e.find(d2 + "/camera_matrix.csv:2: expected 3 "
		                      "comma-separated numbers"),
		          std::string::npos)
		    << e;
	}
	// depth images: of another size, 8-bit; one without its odometry row
	// and a row without its image
	{
		const auto d = makeCapture("bad_depth", noVideo);
		cv::imwrite(d + "/depth/000003.png",
		            cv::Mat(kH + 1, kW, CV_16UC1, cv::Scalar(700)));
		auto e = importError(d);
		EXPECT_NE(e.find(d +
		                 "/depth/000003.png: depth image is 32x25 but the "
		                 "first (" +
		                 d + "/depth/000000.png) is 32x24"),
		          std::string::npos)
		    << e;
		EXPECT_FALSE(fs::exists(d + "/../out.rawlog"));
		EXPECT_FALSE(fs::exists(d + "/../out.rawlog.partial"));
		cv::imwrite(d + "/depth/000003.png",
		            cv::Mat(kH, kW, CV_8UC1, cv::Scalar(7)));
		e = importError(d);
		EXPECT_NE(e.find(d + "/depth/000003.png: depth must be a 16-bit "
		                     "single-channel PNG"),
		          std::string::npos)
		    << e;
		const auto d2 = makeCapture("extra_depth", noVideo);
		cv::imwrite(d2 + "/depth/000006.png",
		            cv::Mat(kH, kW, CV_16UC1, cv::Scalar(700)));
		e = importError(d2);
		EXPECT_NE(e.find(d2 + "/depth/000006.png: frame 6 has no row in " + d2 +
		                 "/odometry.csv"),
		          std::string::npos)
		    << e;
		fs::remove(d2 + "/depth/000006.png");
		fs::remove(d2 + "/depth/000004.png");
		e = importError(d2);
		EXPECT_NE(e.find(d2 + "/odometry.csv:6: frame 4 has no depth image (" +
		                 d2 + "/depth/000004.png)"),
		          std::string::npos)
		    << e;
	}
	// a confidence image missing or of another size (the folder exists)
	{
		const auto d = makeCapture("bad_confidence", noVideo);
		fs::remove(d + "/confidence/000004.png");
		auto e = importError(d);
		EXPECT_NE(e.find(d + "/confidence/000004.png: cannot read confidence "
		                     "image"),
		          std::string::npos)
		    << e;
		cv::imwrite(d + "/confidence/000004.png",
		            cv::Mat(kH / 2, kW / 2, CV_8UC1, cv::Scalar(2)));
		e = importError(d);
		EXPECT_NE(e.find(d + "/confidence/000004.png: confidence image is "
		                     "16x12 but its depth image"),
		          std::string::npos)
		    << e;
		EXPECT_FALSE(fs::exists(d + "/../out.rawlog"));
	}
	testing::internal::GetCapturedStderr();
	// [import_stray]: an unknown key, values out of range, an unknown
	// section: errors naming them
	for (const auto& [text, name] :
	     std::vector<std::pair<std::string, std::string>>{
	         {"[import_stray]\nmin_confidance = 1\n", "min_confidance"},
	         {"[import_stray]\nmin_confidence = 3\n", "min_confidence"},
	         {"[import_stray]\nmin_confidence = -1\n", "min_confidence"},
	         {"[import_stray]\ncolour_width = 0\n", "colour_width"},
	         {"[import_strays]\nmin_confidence = 1\n", "import_strays"},
	         {"[sensors]\nimu_lable = X\n", "imu_lable"}})
	{
		mrpt::config::CConfigFileMemory ini(text);
		ev::StrayImportParams p;
		try
		{
			p.loadFromConfigFile(ini);
			ADD_FAILURE() << text;
		}
		catch (const bims::ConfigError& e)
		{
			EXPECT_NE(std::string(e.what()).find(name), std::string::npos)
			    << e.what();
		}
	}
	// the preset reads
	mrpt::config::CConfigFile preset(std::string(BIMS_SOURCE_DIR) +
	                                 "/config/stray.ini");
	ev::StrayImportParams p;
	p.min_confidence = 0;
	p.loadFromConfigFile(preset);
	EXPECT_EQ(p.min_confidence, 1);
	EXPECT_EQ(p.colour_width, 1920);
	EXPECT_EQ(p.colour_height, 1440);
	EXPECT_EQ(p.rgbd_label, "RGBD");
	EXPECT_EQ(p.imu_label, "IMU");
}

TEST(ImportStray, RealCaptureSpecificForceIsArkitsUp)
{
	const std::string src = bims::test::kStrayEarly;
	if (!fs::exists(src + "/odometry.csv"))
		GTEST_SKIP() << "no Stray sample (" << src << ")";
	const auto d = bims::test::freshTmpDir("bims_test_stray", "real");
	const std::string out = d + "/s.rawlog";
	const std::string config =
	    std::string(BIMS_SOURCE_DIR) + "/config/stray.ini";
	const auto run = bims::test::runCommand(
	    std::string(BIMS_BIN_DIR) + "/bims-import-stray " + src + " -o " + out +
	    " -c " + config + " --max-frames 60 -q");
	ASSERT_EQ(run.code, 0) << run.out;
	const std::string& report = run.out;
	EXPECT_NE(report.find("60 RGB-D frames of 256x192 (no colour"),
	          std::string::npos)
	    << report;
	EXPECT_EQ(count(report, "rgb.mp4: not found"), 1u) << report;

	// odometry.csv read on its own: stamp and pose of each row
	std::vector<std::array<double, 8>> odo;
	{
		std::ifstream f(src + "/odometry.csv");
		std::string l;
		std::getline(f, l);
		while (std::getline(f, l))
		{
			std::array<double, 8> r{};
			long frame = 0;
			ASSERT_EQ(std::sscanf(l.c_str(),
			                      "%lf, %ld, %lf, %lf, %lf, %lf, %lf, %lf, %lf",
			                      &r[0], &frame, &r[1], &r[2], &r[3], &r[4],
			                      &r[5], &r[6], &r[7]),
			          9)
			    << l;
			EXPECT_EQ(frame, static_cast<long>(odo.size()));
			odo.push_back(r);
		}
	}
	ASSERT_GT(odo.size(), 60u);

	// R_IC from the preset: R_CI = R_IC^T maps the IMU into the camera
	mrpt::config::CConfigFile ini(config);
	std::istringstream rs(ini.read_string("calibration", "R_IC", ""));
	Eigen::Matrix3d R_IC;
	for (int j = 0; j < 9; j++) rs >> R_IC(j / 3, j % 3);
	ASSERT_TRUE(rs) << "R_IC of config/stray.ini";
	const Eigen::Matrix3d R_CI = R_IC.transpose();

	size_t scans = 0, imu = 0;
	Eigen::Vector3d f = Eigen::Vector3d::Zero();
	double tFirstImu = -1, tSum = 0;
	for (const auto& ob : readAll(out))
	{
		if (auto s = std::dynamic_pointer_cast<CObservation3DRangeScan>(ob))
		{
			EXPECT_EQ(s->rangeImage.cols(), 256);
			EXPECT_EQ(s->rangeImage.rows(), 192);
			EXPECT_FALSE(s->hasIntensityImage);
			EXPECT_NEAR(stampOf(*s), odo[scans][0], 1e-6) << scans;
			// camera_matrix.csv x 256/1920
			EXPECT_NEAR(s->cameraParams.fx(), 1327.616 * 256 / 1920, 1e-9);
			scans++;
		}
		else if (auto m = std::dynamic_pointer_cast<CObservationIMU>(ob))
		{
			const double t = stampOf(*m);
			if (tFirstImu < 0) tFirstImu = t;
			EXPECT_LE(t, odo[59][0] + 1e-9);
			if (t < tFirstImu + 0.5)
			{
				f += Eigen::Vector3d(m->get(mrpt::obs::IMU_X_ACC),
				                     m->get(mrpt::obs::IMU_Y_ACC),
				                     m->get(mrpt::obs::IMU_Z_ACC));
				tSum += t;
				imu++;
			}
		}
	}
	EXPECT_EQ(scans, 60u);
	ASSERT_GT(imu, 30u);  // ~100 Hz
	f /= double(imu);
	EXPECT_NEAR(f.norm(), 9.8, 0.5) << f.transpose();
	// ARKit's up (world y) in the camera at the middle of that half second
	const double tMid = tSum / double(imu);
	size_t near = 0;
	for (size_t j = 0; j < odo.size(); j++)
		if (std::abs(odo[j][0] - tMid) < std::abs(odo[near][0] - tMid))
			near = j;
	const auto& r = odo[near];
	const Eigen::Matrix3d R_WC = Eigen::Quaterniond(r[7], r[4], r[5], r[6])
	                                 .normalized()
	                                 .toRotationMatrix();
	const Eigen::Vector3d upC = R_WC.transpose() * Eigen::Vector3d::UnitY();
	const Eigen::Vector3d fC = R_CI * f;
	const double deg =
	    std::acos(std::clamp(fC.normalized().dot(upC), -1.0, 1.0)) * 180 / M_PI;
	EXPECT_LT(deg, 10.0) << "specific force in the camera "
	                     << fC.normalized().transpose() << ", ARKit's up "
	                     << upC.transpose();

	// the reference: the 39 rows without position left out
	const auto ref = bims::loadTumTrajectory(d + "/s_arkit_reference.txt");
	ASSERT_EQ(ref.size(), 60u - 39u);
	EXPECT_NEAR(ref.front().t, odo[39][0], 1e-6);
	EXPECT_NE(report.find("the first 39 frames left out"), std::string::npos)
	    << report;
}

TEST(ImportStray, TheProgramTakesItsCommandLine)
{
	const std::string bin = std::string(BIMS_BIN_DIR) + "/bims-import-stray";
	const auto h = bims::test::runCommand(bin + " --help");
	EXPECT_EQ(h.code, 0) << h.out;
	EXPECT_NE(h.out.find("USAGE"), std::string::npos) << h.out;
	EXPECT_NE(h.out.find("--max-frames"), std::string::npos) << h.out;

	const auto d = makeCapture("cli");
	const std::string out = d + "/../cli.rawlog";
	fs::remove(out);  // of an earlier run of this test
	fs::remove(d + "/../cli_arkit_reference.txt");
	auto r = bims::test::runCommand(bin + " " + d + "/../nothing -o " + out);
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_NE(r.out.find("bims-import-stray: error: " + d +
	                     "/../nothing: not a directory"),
	          std::string::npos)
	    << r.out;
	r = bims::test::runCommand(bin + " " + d + " -o " + out + " --gz 10");
	EXPECT_EQ(r.code, 2) << r.out;
	EXPECT_NE(r.out.find("--gz must be in 0..9"), std::string::npos) << r.out;
	// an output that is an input
	r = bims::test::runCommand(bin + " " + d + " -o " + d);
	EXPECT_EQ(r.code, 2) << r.out;
	EXPECT_FALSE(fs::exists(out));

	// an existing output is replaced, as bims-import-tum does (written
	// whole under OUT.partial, then renamed)
	std::ofstream(out) << "an earlier file";
	std::ofstream(d + "/../cli_arkit_reference.txt") << "an earlier file";
	r = bims::test::runCommand(bin + " " + d + " -o " + out + " -q --gz 0");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find(out + ": 6 RGB-D frames of 32x24 (colour from "
	                           "rgb.mp4, 128x96 resized)"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("the first 2 frames left out"), std::string::npos)
	    << r.out;
	EXPECT_EQ(r.out.find(" frames ("), std::string::npos)
	    << "-q: no progress line\n"
	    << r.out;
	size_t scans = 0;
	for (const auto& o : readAll(out))
		scans +=
		    std::dynamic_pointer_cast<CObservation3DRangeScan>(o) != nullptr;
	EXPECT_EQ(scans, size_t(kFrames));
	EXPECT_EQ(bims::loadTumTrajectory(d + "/../cli_arkit_reference.txt").size(),
	          size_t(kFrames - 2));
	// --max-frames and the progress line (stderr is not a terminal here)
	r = bims::test::runCommand(bin + " " + d + " -o " + out +
	                           " --max-frames 4 -c " + BIMS_SOURCE_DIR +
	                           "/config/stray.ini");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("bims-import-stray: 4/4 frames (100 %)"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find(out + ": 4 RGB-D frames"), std::string::npos) << r.out;
}
