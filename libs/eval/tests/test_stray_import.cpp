// bims-import-stray (stray_import.h; its run: bims/apps/stray_import_run.h): a
// Stray Scanner capture made by the test itself, imported and checked
// convention by convention; bad input; the shared real capture (skipped without
// it); the built program's command line.
#include <bims/common/config.h>
#include <bims/eval/stray_import.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/sensors/camera.h>
#include <bims_test/data.h>
#include <bims_test/run_command.h>
#include <bims_test/text.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/poses/CPose3DQuat.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>

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
	// no newline after the last row, as Stray writes it; of the video's
	// size, or without one of [import_stray]'s default colour size
	// (1920x1440, 15 times the video's): the same view either way
	std::ofstream(d + "/camera_matrix.csv")
	    << (spec.video ? "100.0, 0.0, 64.5\n0.0, 96.0, 47.25\n0.0, 0.0, 1.0"
	                   : "1500.0, 0.0, 967.5\n0.0, 1440.0, 708.75\n0.0, 0.0, "
	                     "1.0");
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
	o.warn = {};  // what the capture lacks: not said
	return o;
}

/** quiet() but what the capture lacks collected into \a said ("WHERE:
 * TEXT" lines). */
ev::StrayImportOptions telling(std::string& said)
{
	ev::StrayImportOptions o = quiet();
	o.warn = [&said](const bims::Warning& w)
	{ said += w.where + ": " + w.text + "\n"; };
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
	std::string err;
	const auto sum =
	    ev::importStray(d, d + "/../novideo.rawlog", {}, telling(err));
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
			EXPECT_DOUBLE_EQ(s->cameraParams.fx(), 1500.0 * 32 / 1920);
			EXPECT_DOUBLE_EQ(s->cameraParams.cy(), 708.75 * 24 / 1440);
		}
	EXPECT_EQ(scans, size_t(kFrames));
	// the colour size from the .ini
	mrpt::config::CConfigFileMemory ini(
	    "[import_stray]\ncolour_width = 2400\ncolour_height = 1800\n");
	ev::StrayImportParams p;
	p.loadFromConfigFile(ini);
	testing::internal::CaptureStderr();
	const auto s2 = ev::importStray(d, d + "/../novideo2.rawlog", p, quiet());
	testing::internal::GetCapturedStderr();
	EXPECT_DOUBLE_EQ(s2.camera.fx(), 1500.0 * 32 / 2400);
	EXPECT_DOUBLE_EQ(s2.camera.cx(), 967.5 * 32 / 2400);
}

TEST(ImportStray, WithoutConfidenceEveryReadingIsKeptAndItIsSaidOnce)
{
	CaptureSpec spec;
	spec.confidence = false;
	spec.imu = false;
	const auto d = makeCapture("noconf", spec);
	std::string err;
	const auto sum =
	    ev::importStray(d, d + "/../noconf.rawlog", {}, telling(err));
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

// Issue 55, item 3 and the unclear messages: inputs that are not regular
// files (a FIFO blocked the import forever, /dev/zero ate memory) are
// refused naming the file and what it is; a symbolic link loop is named
// as one; a confidence "folder" that is a file is said to be one. A failed
// import leaves no partial rawlog.
TEST(ImportStray, InputsThatAreNotRegularFilesAreRefusedNamingThem)
{
	CaptureSpec noVideo;
	noVideo.video = false;
	const auto leavesNothing = [](const std::string& d)
	{
		for (const auto& e : fs::directory_iterator(d + "/.."))
			EXPECT_EQ(e.path().string().find("out.rawlog"), std::string::npos)
			    << e.path();
	};
	bool fifos = true;
	for (const std::string file :
	     {"odometry.csv", "imu.csv", "depth/000003.png", "rgb.mp4",
	      "confidence/000002.png"})
	{
		std::string name = "fifo_" + file;
		std::replace(name.begin(), name.end(), '/', '_');
		const auto d =
		    makeCapture(name, file == "rgb.mp4" ? CaptureSpec{} : noVideo);
		fs::remove(d + "/" + file);
		if (::mkfifo((d + "/" + file).c_str(), 0600) != 0)
		{
			fifos = false;
			break;
		}
		// (without the rule: blocked until the test's timeout)
		const auto e = importError(d);
		EXPECT_NE(e.find(d + "/" + file + ": cannot read "), std::string::npos)
		    << e;
		EXPECT_NE(e.find("a FIFO (named pipe), not a regular file"),
		          std::string::npos)
		    << e;
		leavesNothing(d);
	}
	// /dev/zero (only read) linked as the IMU's file
	{
		const auto d = makeCapture("zero_imu", noVideo);
		fs::remove(d + "/imu.csv");
		fs::create_symlink("/dev/zero", d + "/imu.csv");
		const auto e = importError(d);
		EXPECT_NE(e.find(d + "/imu.csv: cannot read CSV file: a character "
		                     "device, not a regular file"),
		          std::string::npos)
		    << e;
	}
	// a symbolic link loop: named as one, not "not found"
	{
		const auto d = makeCapture("loop", noVideo);
		fs::remove(d + "/odometry.csv");
		fs::create_symlink("odometry2.csv", d + "/odometry.csv");
		fs::create_symlink("odometry.csv", d + "/odometry2.csv");
		const auto e = importError(d);
		EXPECT_NE(e.find(d + "/odometry.csv: cannot read CSV file: a symbolic "
		                     "link loop"),
		          std::string::npos)
		    << e;
	}
	// confidence: a file where the folder goes
	{
		const auto d = makeCapture("confidence_file", noVideo);
		fs::remove_all(d + "/confidence");
		std::ofstream(d + "/confidence") << "not a folder";
		const auto e = importError(d);
		EXPECT_NE(e.find(d + "/confidence: not a folder of ARKit confidence "
		                     "images (a file)"),
		          std::string::npos)
		    << e;
	}
	if (!fifos) GTEST_SKIP() << "mkfifo refused here: FIFOs not tried";
}

// Issue 55, item 4 and the unclear messages: the CSVs are read row by row
// with a line's length bounded (a file of one endless line: an error with
// file and line, not gigabytes); a byte-order mark before the header is
// skipped and CR-only line ends are lines.
TEST(ImportStray, CsvLinesAreBoundedAndBomOrCrOnlyFilesAreRead)
{
	CaptureSpec noVideo;
	noVideo.video = false;
	const auto d = makeCapture("long_line", noVideo);
	{
		std::ofstream f(d + "/imu.csv", std::ios::binary);
		f << "timestamp, a_x, a_y, a_z, alpha_x, alpha_y, alpha_z\n";
		f << std::string(3 << 20, '\0');  // 3 MB, no line end
	}
	auto e = importError(d);
	EXPECT_NE(e.find(d + "/imu.csv:2: a line longer than 65536 bytes"),
	          std::string::npos)
	    << e;
	// a BOM, CR-only line ends: the same import as the plain files
	const auto plain = makeCapture("plain_csv", noVideo);
	testing::internal::CaptureStderr();
	const auto want =
	    ev::importStray(plain, plain + "/../plain.rawlog", {}, quiet());
	const auto edit = [](const std::string& path, bool bom, bool crOnly)
	{
		std::string text = bims::test::fileText(path);
		if (crOnly) std::replace(text.begin(), text.end(), '\n', '\r');
		std::ofstream(path, std::ios::binary)
		    << (bom ? "\xEF\xBB\xBF" : "") << text;
	};
	const auto odd = makeCapture("odd_csv", noVideo);
	edit(odd + "/odometry.csv", true, false);
	edit(odd + "/imu.csv", false, true);
	edit(odd + "/camera_matrix.csv", true, true);
	const auto got = ev::importStray(odd, odd + "/../odd.rawlog", {}, quiet());
	testing::internal::GetCapturedStderr();
	EXPECT_EQ(got.frames, want.frames);
	EXPECT_EQ(got.imu, want.imu);
	EXPECT_EQ(got.camera.fx(), want.camera.fx());
	const auto a = bims::loadTumTrajectory(odd + "/../odd_arkit_reference.txt");
	const auto b =
	    bims::loadTumTrajectory(plain + "/../plain_arkit_reference.txt");
	ASSERT_EQ(a.size(), b.size());
	for (size_t i = 0; i < a.size(); i++) EXPECT_EQ(a[i].t, b[i].t);
	// a BOM in the middle of a header is shown, not printed raw
	std::ofstream(odd + "/imu.csv")
	    << "timestamp, a_x,\xEF\xBB\xBF a_y, a_z, alpha_x, alpha_y, alpha_z\n";
	e = importError(odd);
	EXPECT_NE(e.find("\\xEF\\xBB\\xBF"), std::string::npos) << e;
}

// Issue 55, item 6: intrinsics that cannot be are refused, saying what is
// accepted; a video of another size than camera_matrix.csv's colour stream
// is scaled when its aspect ratio agrees, refused otherwise.
TEST(ImportStray, IntrinsicsThatCannotBeAreRefused)
{
	namespace sn = bims::sensors;
	EXPECT_EQ(sn::intrinsicsProblem({256, 192, 177, 177, 129.3, 95.4}), "");
	EXPECT_NE(sn::intrinsicsProblem({256, 192, 177, 177, -129, 1.3e8})
	              .find("the principal point (cx -129, cy 1.3e+08) is outside "
	                    "the 256x192 image (accepted: 0 <= cx <= 256, 0 <= cy "
	                    "<= 192)"),
	          std::string::npos);
	const std::string far =
	    sn::intrinsicsProblem({256, 192, 1e300, 177, 128, 96});
	EXPECT_NE(far.find("fx 1e+300 gives a field of view of 0 deg"),
	          std::string::npos)
	    << far;
	EXPECT_NE(far.find("accepted: 10 to 160 deg"), std::string::npos) << far;
	// a K of 1280x960 on 64x48 images
	EXPECT_NE(sn::intrinsicsProblem({64, 48, 1000, 1000, 640, 480})
	              .find("outside the 64x48 image"),
	          std::string::npos);
	EXPECT_NE(sn::intrinsicsProblem({64, 48, 1000, 1000, 32, 24})
	              .find("fx 1000 gives a field of view of 3.67 deg"),
	          std::string::npos);

	CaptureSpec noVideo;
	noVideo.video = false;
	const auto d = makeCapture("bad_intrinsics", noVideo);
	std::ofstream(d + "/camera_matrix.csv")
	    << "1500, 0, -129\n0, 1440, 1.3e8\n0, 0, 1\n";
	auto e = importError(d);
	EXPECT_NE(
	    e.find(d + "/camera_matrix.csv (of a 1920x1440 colour image, "
	               "scaled to the 32x24 depth grid): the principal point"),
	    std::string::npos)
	    << e;
	EXPECT_FALSE(fs::exists(d + "/../out.rawlog"));
	std::ofstream(d + "/camera_matrix.csv")
	    << "1e300, 0, 960\n0, 1440, 720\n0, 0, 1\n";
	e = importError(d);
	EXPECT_NE(e.find("fx 1.66667e+298 gives a field of view of 0 deg"),
	          std::string::npos)
	    << e;

	// a re-encoded video (of the 1920x1440 stream's aspect ratio, 128x96)
	// with camera_matrix.csv of the 1920x1440 stream: scaled from 1920x1440
	const auto v = makeCapture("reencoded");
	std::ofstream(v + "/camera_matrix.csv")
	    << "1500.0, 0.0, 967.5\n0.0, 1440.0, 708.75\n0.0, 0.0, 1.0";
	const auto sum =
	    ev::importStray(v, v + "/../reencoded.rawlog", {}, quiet());
	EXPECT_DOUBLE_EQ(sum.camera.fx(), 25.0);
	EXPECT_DOUBLE_EQ(sum.camera.cx(), 967.5 * 32 / 1920);
	ASSERT_EQ(sum.notes.size(), 1u);
	EXPECT_NE(sum.notes[0].find("rgb.mp4: frames of 128x96, " + v +
	                            "/camera_matrix.csv of the 1920x1440 colour "
	                            "stream"),
	          std::string::npos)
	    << sum.notes[0];
	// ... and of another aspect ratio than that stream: refused
	mrpt::config::CConfigFileMemory ini(
	    "[import_stray]\ncolour_width = 1920\ncolour_height = 1080\n");
	ev::StrayImportParams p;
	p.loadFromConfigFile(ini);
	e = importError(v, p);
	EXPECT_NE(e.find(v +
	                 "/rgb.mp4: frames of 128x96, but the principal point "
	                 "of " +
	                 v +
	                 "/camera_matrix.csv (cx 967.5, cy 708.75) is not "
	                 "near their centre"),
	          std::string::npos)
	    << e;
}

// Issue 55, item 7: stamps the rawlog cannot hold are refused with what is
// accepted; frames on one 100 ns tick of the rawlog's clock are left out
// and counted, never dropped without a word.
TEST(ImportStray, TimeStampsAreRefusedOrCountedNeverWrapped)
{
	CaptureSpec noVideo;
	noVideo.video = false;
	const auto d = makeCapture("negative_time", noVideo);
	auto lines = [](const std::string& path)
	{
		std::vector<std::string> v;
		std::istringstream in(bims::test::fileText(path));
		for (std::string l; std::getline(in, l);) v.push_back(l);
		return v;
	};
	auto odo = lines(d + "/odometry.csv");
	const auto rewrite =
	    [&](const std::string& path, const std::vector<std::string>& rows)
	{
		std::ofstream f(path);
		for (const auto& r : rows) f << r << "\n";
	};
	auto bad = odo;
	bad[1] = "-10000000" + bad[1].substr(bad[1].find(','));
	rewrite(d + "/odometry.csv", bad);
	auto e = importError(d);
	EXPECT_NE(e.find(d + "/odometry.csv:2: timestamp -10000000 is not a time "
	                     "bims takes: seconds from 0 to 4294967295"),
	          std::string::npos)
	    << e;
	bad = odo;
	bad[6] = "1e12" + bad[6].substr(bad[6].find(','));
	rewrite(d + "/odometry.csv", bad);
	e = importError(d);
	EXPECT_NE(e.find(d + "/odometry.csv:7: timestamp 1e+12 is not a time"),
	          std::string::npos)
	    << e;

	// frames 2 and 3 within one tick (0.1 and 0.4 of it): frame 3 left out
	// and counted, the reference without it too
	const auto c = makeCapture("same_tick");
	odo = lines(c + "/odometry.csv");
	odo[3] = "248630.60330001" + odo[3].substr(odo[3].find(','));
	odo[4] = "248630.60330004" + odo[4].substr(odo[4].find(','));
	rewrite(c + "/odometry.csv", odo);
	const auto sum = ev::importStray(c, c + "/../tick.rawlog", {}, quiet());
	EXPECT_EQ(sum.framesSameStamp, 1u);
	EXPECT_EQ(sum.frames, size_t(kFrames - 1));
	EXPECT_EQ(sum.referencePoses, size_t(kFrames - 3));
	ASSERT_FALSE(sum.warnings.empty());
	EXPECT_NE(sum.warnings.back().find(c + "/odometry.csv: 1 frames left out: "
	                                       "each within the 100 ns tick"),
	          std::string::npos)
	    << sum.warnings.back();
	// the frames after it keep their colour (the video frame skipped too)
	std::vector<double> stamps;
	for (const auto& o : readAll(c + "/../tick.rawlog"))
		if (auto s = std::dynamic_pointer_cast<CObservation3DRangeScan>(o))
		{
			stamps.push_back(stampOf(*s));
			if (stamps.size() == 5)  // frame 5's: colour 5
			{
				const auto px =
				    s->intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY)
				        .at<cv::Vec3b>(12, 16);
				for (int ch = 0; ch < 3; ch++)
					EXPECT_NEAR(px[ch], colour(5)[ch], 40) << ch;
			}
		}
	ASSERT_EQ(stamps.size(), size_t(kFrames - 1));
	for (size_t i = 1; i < stamps.size(); i++)
		EXPECT_GT(stamps[i], stamps[i - 1]);
}

// Issue 55, item 8: an IMU on another clock or in other units: the samples
// left out are counted and said, naming the file and why.
TEST(ImportStray, AnImuOnAnotherClockIsCountedAndSaid)
{
	CaptureSpec noVideo;
	noVideo.video = false;
	const auto d = makeCapture("imu_clock", noVideo);
	// the IMU in milliseconds: every sample after the last frame
	std::ofstream imu(d + "/imu.csv");
	imu << "timestamp, a_x, a_y, a_z, alpha_x, alpha_y, alpha_z\n";
	const auto rows = imuRows();
	for (const auto& r : rows)
		imu << std::to_string(r.t * 1000) << ", 0.1, -9.8, 0.2, 0, 0, 0\n";
	imu.close();
	testing::internal::CaptureStderr();
	const auto sum =
	    ev::importStray(d, d + "/../imu_clock.rawlog", {}, quiet());
	testing::internal::GetCapturedStderr();
	EXPECT_EQ(sum.imu, 0u);
	EXPECT_EQ(sum.imuAfterLast, rows.size());
	ASSERT_GE(sum.warnings.size(), 2u);
	EXPECT_NE(
	    sum.warnings[0].find(d + "/imu.csv: " + std::to_string(rows.size()) +
	                         " of its " + std::to_string(rows.size()) +
	                         " samples are after the capture's last frame"),
	    std::string::npos)
	    << sum.warnings[0];
	EXPECT_NE(sum.warnings[0].find("is the IMU on odometry.csv's clock and "
	                               "in seconds?"),
	          std::string::npos)
	    << sum.warnings[0];
	EXPECT_NE(sum.warnings[1].find("none of its"), std::string::npos)
	    << sum.warnings[1];
	// the program says it on stderr and in its report
	const std::string bin = std::string(BIMS_BIN_DIR) + "/bims-import-stray";
	const auto r = bims::test::runCommand(bin + " " + d + " -q -o " + d +
	                                      "/../imu_clock2.rawlog");
	EXPECT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("bims-import-stray: warning: " + d + "/imu.csv: " +
	                     std::to_string(rows.size()) + " of its"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find(std::to_string(rows.size()) +
	                     " IMU samples after the last frame"),
	          std::string::npos)
	    << r.out;
}

// Issue 55, items 1 and 11: an output that is a FIFO or a device is
// refused, never replaced by a file; two runs of one output at once leave
// one run's rawlog and reference, whole.
TEST(ImportStray, OutputsAreNeverDevicesAndTwoRunsNeverMix)
{
	const std::string bin = std::string(BIMS_BIN_DIR) + "/bims-import-stray";
	CaptureSpec noVideo;
	noVideo.video = false;
	const auto d = makeCapture("out_special", noVideo);
	const std::string fifo = d + "/../out_fifo.rawlog";
	fs::remove(fifo);
	if (::mkfifo(fifo.c_str(), 0600) == 0)
	{
		const auto r = bims::test::runCommand(bin + " " + d + " -q -o " + fifo);
		EXPECT_EQ(r.code, 1) << r.out;
		EXPECT_NE(r.out.find(fifo + ": is a FIFO (named pipe), not a regular "
		                            "file"),
		          std::string::npos)
		    << r.out;
		EXPECT_TRUE(fs::is_fifo(fifo));
	}
	// a character device of its own (root only): mknod c 1 3 is /dev/null
	const std::string dev = d + "/../out_dev.rawlog";
	fs::remove(dev);
	if (::mknod(dev.c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0)
	{
		const auto r = bims::test::runCommand(bin + " " + d + " -q -o " + dev);
		EXPECT_EQ(r.code, 1) << r.out;
		EXPECT_NE(r.out.find(dev + ": is a character device"),
		          std::string::npos)
		    << r.out;
		EXPECT_TRUE(fs::is_character_file(dev));
		fs::remove(dev);
	}

	// two runs at once into one output, 400 and 200 frames of 256x192 (long
	// enough for their writing to overlap), three times
	const auto big = bims::test::freshTmpDir("bims_test_stray", "big");
	{
		fs::create_directories(big + "/depth");
		std::ofstream odo(big + "/odometry.csv");
		odo << "timestamp, frame, x, y, z, qx, qy, qz, qw\n";
		std::vector<uint8_t> png;
		cv::Mat depth(192, 256, CV_16UC1);
		cv::randu(depth, 300, 3000);  // (incompressible: ~100 kB a frame)
		cv::imencode(".png", depth, png);
		for (int k = 0; k < 400; k++)
		{
			char n[16];
			std::snprintf(n, sizeof(n), "%06d", k);
			std::ofstream(big + "/depth/" + n + ".png", std::ios::binary)
			    .write(reinterpret_cast<const char*>(png.data()),
			           static_cast<std::streamsize>(png.size()));
			odo << 100 + 0.02 * k << ", " << n << ", " << (k < 2 ? 0 : 0.01 * k)
			    << ", 0, 0, 0, 0, 0, 1\n";
		}
		std::ofstream(big + "/camera_matrix.csv")
		    << "1400, 0, 960\n0, 1400, 720\n0, 0, 1\n";
	}
	const std::string out = d + "/../both.rawlog";
	const std::string ref = d + "/../both_arkit_reference.txt";
	for (int round = 0; round < 3; round++)
	{
		const auto r = bims::test::runCommand(
		    "(" + bin + " " + big + " -q --gz 0 -o " + out + " & " + bin + " " +
		    big + " -q --gz 0 --max-frames 200 -o " + out + " & wait)");
		size_t scans = 0;
		try
		{
			for (const auto& o : readAll(out))
				scans += std::dynamic_pointer_cast<CObservation3DRangeScan>(
				             o) != nullptr;
		}
		catch (const std::exception& e)
		{
			ADD_FAILURE() << "round " << round << ": " << e.what();
		}
		EXPECT_TRUE(scans == 400 || scans == 200) << scans << "\n" << r.out;
		// the reference of the same run: 2 frames without position
		EXPECT_EQ(bims::loadTumTrajectory(ref).size(), scans - 2) << r.out;
		for (const auto& e : fs::directory_iterator(d + "/.."))
			EXPECT_EQ(e.path().filename().string().find("both.rawlog."),
			          std::string::npos)
			    << "a partial file left: " << e.path();
	}
	if (!fs::exists(fifo))
		GTEST_SKIP() << "mkfifo refused here: the FIFO output not tried";
}
