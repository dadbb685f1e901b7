// End-to-end tests of bims-sim and bims-info: rawlog round trip through MRPT,
// rawlog-edit, determinism, bad input, the bundled sample.
#include <bims/common/frames.h>
#include <bims/io/output_paths.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/sim/scene.h>
#include <bims/sim/simulator.h>
#include <bims_test/run_command.h>
#include <gtest/gtest.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CRawlog.h>

#include <opencv2/imgcodecs.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <tuple>
#include "bims_test/text.h"

namespace
{
const std::string kBin = BIMS_BIN_DIR;
const std::string kSrc = BIMS_SOURCE_DIR;

std::string tmpDir(const std::string& name)
{
	const std::string d =
	    std::string(BIMS_BINARY_DIR) + "/test_sim_tmp/" + name;
	std::system(("rm -rf '" + d + "' && mkdir -p '" + d + "'").c_str());
	return d;
}

/** The partial file of NAME in \a dir (NAME.PID-TAG.partial, a run's own:
 * bims/io/output_paths.h); "" when there is none. */
std::string partialOf(const std::string& dir, const std::string& name)
{
	for (const auto& e : std::filesystem::directory_iterator(dir))
		if (bims::partialTarget(e.path().filename().string()) == name)
			return e.path().string();
	return "";
}
/** Runs a shell command; returns the exit code, output (stdout+stderr) in out.
 */
int run(const std::string& cmd, std::string& out)
{
	FILE* p = popen((cmd + " 2>&1").c_str(), "r");
	if (!p) return -1;
	char buf[4096];
	out.clear();
	size_t n;
	while ((n = fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
	const int st = pclose(p);
	return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}
void writeFile(const std::string& path, const std::string& text)
{
	std::ofstream(path) << text;
}

const char* kSmallScene = R"([sim]
frames=12
fps=30

[camera]
resolution=320x240

[pendulum]
pivot=0.6 0 2.3
length=1.3
ball_radius=0.25

[box]
center=0.8 0
)";

/** Runs bims-sim on a small scene into dir/out.rawlog. */
std::string simulate(const std::string& dir, const std::string& scene,
                     const std::string& args)
{
	writeFile(dir + "/scene.ini", scene);
	std::string out;
	const int rc = run("'" + kBin + "/bims-sim' '" + dir + "/scene.ini' -o '" +
	                       dir + "/out.rawlog' -q " + args,
	                   out);
	EXPECT_EQ(rc, 0) << out;
	return dir + "/out.rawlog";
}
}  // namespace

TEST(BimsSim, RawlogRoundTripsThroughMrptReader)
{
	const std::string d = tmpDir("roundtrip");
	const std::string f = simulate(d, kSmallScene, "--seed 3");
	mrpt::obs::CRawlog rl;
	ASSERT_TRUE(rl.loadFromRawLogFile(f));
	size_t n3d = 0, nImu = 0;
	double lastT = 0;
	for (size_t i = 0; i < rl.size(); i++)
	{
		ASSERT_EQ(rl.getType(i), mrpt::obs::CRawlog::etObservation);
		const auto o = rl.getAsObservation(i);
		const double t = mrpt::Clock::toDouble(o->timestamp);
		EXPECT_GE(t, lastT) << "rawlog must be time-ordered";
		lastT = t;
		if (auto s =
		        std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
		            o))
		{
			n3d++;
			EXPECT_EQ(s->sensorLabel, "RGBD");
			EXPECT_EQ(s->rangeImage.cols(), 320);
			EXPECT_EQ(s->rangeImage.rows(), 240);
			EXPECT_EQ(s->intensityImage.getWidth(), 320u);
			EXPECT_TRUE(s->range_is_depth);
			EXPECT_FLOAT_EQ(s->rangeUnits, 0.001f);
			EXPECT_NEAR(s->cameraParams.fx(), 262.5, 1e-9);
			EXPECT_TRUE(s->hasPixelLabels());
		}
		else if (std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o))
		{
			nImu++;
			EXPECT_EQ(o->sensorLabel, "IMU");
		}
	}
	EXPECT_EQ(n3d, 12u);
	EXPECT_EQ(nImu, 39u);  // 0 .. 11/30 s + half a frame, at 100 Hz
	// Ground truth files exist, one pose and one mask per frame.
	const std::string gt = d + "/out_gt";
	EXPECT_EQ(bims::loadTumTrajectory(gt + "/groundtruth.txt").size(), 12u);
	const cv::Mat m =
	    cv::imread(gt + "/masks/000011.png", cv::IMREAD_UNCHANGED);
	ASSERT_FALSE(m.empty());
	EXPECT_EQ(m.type(), CV_8UC1);
	EXPECT_EQ(m.cols, 320);
	EXPECT_FALSE(bims::test::fileText(gt + "/imu.txt").empty());
	EXPECT_NE(bims::test::fileText(gt + "/objects.txt").find(" pendulum "),
	          std::string::npos);
	EXPECT_NE(bims::test::fileText(gt + "/calibration.ini").find("R_IC="),
	          std::string::npos);
}

// [rgb] enabled = false: a depth-only sensor. The scans carry no intensity
// image, the depth is the same as with one (same seed).
TEST(BimsSim, WithoutRgbTheScansAreDepthOnlyWithTheSameDepth)
{
	const std::string a = tmpDir("with_rgb"), b = tmpDir("depth_only");
	mrpt::obs::CRawlog ra, rb;
	ASSERT_TRUE(ra.loadFromRawLogFile(simulate(a, kSmallScene, "--seed 3")));
	ASSERT_TRUE(rb.loadFromRawLogFile(simulate(
	    b, std::string(kSmallScene) + "\n[rgb]\nenabled=false\n", "--seed 3")));
	ASSERT_EQ(ra.size(), rb.size());
	size_t scans = 0;
	for (size_t i = 0; i < ra.size(); i++)
	{
		const auto sa =
		    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
		        ra.getAsObservation(i));
		const auto sb =
		    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
		        rb.getAsObservation(i));
		ASSERT_EQ(!sa, !sb) << i;
		if (!sa) continue;
		++scans;
		EXPECT_TRUE(sa->hasIntensityImage);
		EXPECT_FALSE(sb->hasIntensityImage);
		EXPECT_TRUE(sb->intensityImage.isEmpty());
		EXPECT_TRUE(sa->rangeImage == sb->rangeImage) << "scan " << scans;
	}
	EXPECT_EQ(scans, 12u);
}

TEST(BimsSim, RawlogEditListsBothSensorsAtTheirRates)
{
	std::string out;
	if (run("command -v rawlog-edit", out) != 0)
		GTEST_SKIP() << "rawlog-edit not installed";
	const std::string d = tmpDir("rawlogedit");
	const std::string f = simulate(d, kSmallScene, "--max-frames 31");
	ASSERT_EQ(run("rawlog-edit --info -i '" + f + "'", out), 0) << out;
	std::map<std::string, double> rate;
	const std::regex re(
	    R"(Sensor \(Label/Occurs/Rate/Durat\.\)\s*:\s*(\S+)\s*/\s*(\d+)\s*/\s*([0-9.]+))");
	for (std::sregex_iterator it(out.begin(), out.end(), re), end; it != end;
	     ++it)
		rate[(*it)[1]] = std::stod((*it)[3]);
	ASSERT_EQ(rate.size(), 2u) << out;
	EXPECT_NEAR(rate["RGBD"], 30.0, 0.01);
	EXPECT_NEAR(rate["IMU"], 100.0, 0.01);
}

TEST(BimsSim, NoiselessDepthUnprojectedWithGroundTruthLiesOnSurfaces)
{
	// Through the whole chain: rawlog -> MRPT unprojection ({S}) -> T_WC from
	// groundtruth.txt -> distance to the scene; masks checked against the
	// surface each pixel's depth comes from.
	const std::string d = tmpDir("geometry");
	const std::string scene =
	    std::string(kSmallScene) + "\n[depth]\nnoiseless=true\n";
	const std::string f = simulate(d, scene, "--max-frames 3");
	const auto cfg = bims::sim::SimConfig::load(d + "/scene.ini");
	const auto world = cfg.buildScene();
	const auto gt = bims::loadTumTrajectory(d + "/out_gt/groundtruth.txt");
	bims::RawlogReader r(f);
	size_t frame = 0, checked = 0, moving = 0;
	while (auto o = r.next())
	{
		auto s =
		    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(o);
		if (!s) continue;
		const double t = frame / 30.0;
		const auto prims = world.primitivesAt(t);
		const cv::Mat mask = cv::imread(
		    d + "/out_gt/masks/" + mrpt::format("%06zu", frame) + ".png",
		    cv::IMREAD_UNCHANGED);
		ASSERT_FALSE(mask.empty());
		mrpt::poses::CPose3D T_CS = bims::T_SC();
		T_CS.inverse();
		const mrpt::poses::CPose3D T_WS = gt[frame].T_WC + T_CS;
		for (int v = 0; v < 240; v += 2)
			for (int u = 0; u < 320; u += 2)
			{
				const uint16_t z = s->rangeImage(v, u);
				if (!z) continue;
				// MRPT's unprojection of one pixel, in {S}
				const double zc = z * 1e-3;
				const mrpt::math::TPoint3D p_S(
				    zc, -(u - s->cameraParams.cx()) / s->cameraParams.fx() * zc,
				    -(v - s->cameraParams.cy()) / s->cameraParams.fy() * zc);
				const auto p_W = T_WS.composePoint(p_S);
				const Eigen::Vector3d x(p_W.x, p_W.y, p_W.z);
				double dS = 1e9, dM = 1e9;
				for (const auto& p : prims)
				{
					const double dist = bims::sim::distanceToSurface(p, x);
					if (p.objectId)
						dM = std::min(dM, dist);
					else
						dS = std::min(dS, dist);
				}
				ASSERT_LT(std::min(dS, dM), 1e-3)
				    << "frame " << frame << " pixel " << u << "," << v;
				if (mask.at<uint8_t>(v, u) == 255)
				{
					EXPECT_LT(dM, 1e-3);
					moving++;
				}
				else
				{
					EXPECT_EQ(mask.at<uint8_t>(v, u), 0);
					EXPECT_LT(dS, 1e-3);
				}
				checked++;
			}
		// Cross-check our pixel formula against MRPT's own unprojection.
		if (frame == 0)
		{
			mrpt::maps::CSimplePointsMap pts;
			mrpt::obs::T3DPointsProjectionParams pp;
			pp.takeIntoAccountSensorPoseOnRobot = false;
			s->unprojectInto(pts, pp);
			ASSERT_GT(pts.size(), 1000u);
			double worst = 0;
			for (size_t i = 0; i < pts.size(); i += 97)
			{
				mrpt::math::TPoint3D q;
				pts.getPoint(i, q);
				const auto p_W = T_WS.composePoint(q);
				worst = std::max(worst, world.distanceToNearestSurface(
				                            {p_W.x, p_W.y, p_W.z}, t));
			}
			EXPECT_LT(worst, 1e-3);
		}
		frame++;
	}
	EXPECT_EQ(frame, 3u);
	EXPECT_GT(checked, 30000u);
	EXPECT_GT(moving, 200u);
}

TEST(BimsSim, SameSeedGivesIdenticalBytesOtherSeedDiffers)
{
	const std::string a = tmpDir("seedA"), b = tmpDir("seedB"),
	                  c = tmpDir("seedC");
	const std::string fa = simulate(a, kSmallScene, "--seed 5 --max-frames 4");
	const std::string fb = simulate(b, kSmallScene, "--seed 5 --max-frames 4");
	const std::string fc = simulate(c, kSmallScene, "--seed 6 --max-frames 4");
	EXPECT_EQ(bims::test::fileText(fa), bims::test::fileText(fb));
	for (const char* g : {"groundtruth.txt", "imu.txt", "objects.txt",
	                      "calibration.ini", "masks/000003.png"})
		EXPECT_EQ(bims::test::fileText(a + "/out_gt/" + g),
		          bims::test::fileText(b + "/out_gt/" + g))
		    << g;
	EXPECT_NE(bims::test::fileText(fa), bims::test::fileText(fc));
	EXPECT_NE(bims::test::fileText(a + "/out_gt/imu.txt"),
	          bims::test::fileText(c + "/out_gt/imu.txt"));
	// Geometry does not depend on the noise seed.
	EXPECT_EQ(bims::test::fileText(a + "/out_gt/groundtruth.txt"),
	          bims::test::fileText(c + "/out_gt/groundtruth.txt"));
	EXPECT_EQ(bims::test::fileText(a + "/out_gt/masks/000003.png"),
	          bims::test::fileText(c + "/out_gt/masks/000003.png"));
}

TEST(BimsSim, BadInputGivesClearErrorAndNonZeroExit)
{
	const std::string d = tmpDir("bad");
	struct Case
	{
		std::string ini, expect;
	};
	const std::vector<Case> cases = {
	    {std::string(kSmallScene) + "\n[depth]\nmax_rnage=4\n",
	     "[depth] max_rnage"},
	    {"[camera]\nresolution=320x240\n", "missing required section [sim]"},
	    {std::string(kSmallScene) + "\n[imu]\nrate_hz=-5\n", "[imu] rate_hz"},
	    {std::string(kSmallScene) + "\n[cmaera]\nfx=500\n", "cmaera"},
	    {"[sim]\nframes=ten\n", "[sim] frames"},
	    {std::string(kSmallScene) +
	         "\n[pendulum2]\nlength=0.5\nball_radius=0.6\n",
	     "[pendulum2] ball_radius"},
	};
	for (size_t i = 0; i < cases.size(); i++)
	{
		const std::string ini = d + "/bad" + std::to_string(i) + ".ini";
		writeFile(ini, cases[i].ini);
		std::string out;
		const int rc = run(
		    "'" + kBin + "/bims-sim' '" + ini + "' -o '" + d + "/x.rawlog' -q",
		    out);
		EXPECT_NE(rc, 0) << cases[i].ini;
		EXPECT_NE(out.find(cases[i].expect), std::string::npos) << out;
		EXPECT_NE(out.find("bad" + std::to_string(i) + ".ini"),
		          std::string::npos)
		    << out;
	}
	std::string out;
	EXPECT_NE(run("'" + kBin + "/bims-sim' '" + d + "/nope.ini' -o '" + d +
	                  "/x.rawlog'",
	              out),
	          0);
	EXPECT_NE(out.find("nope.ini"), std::string::npos) << out;
	EXPECT_EQ(run("'" + kBin + "/bims-sim' -o '" + d + "/x.rawlog'", out), 2)
	    << out;
	writeFile(d + "/good.ini", kSmallScene);
	EXPECT_EQ(run("'" + kBin + "/bims-sim' '" + d +
	                  "/good.ini' -o x.rawlog -r 800x600",
	              out),
	          2);
	EXPECT_NE(out.find("640x480 or 320x240"), std::string::npos) << out;
	EXPECT_EQ(run("'" + kBin + "/bims-sim' '" + d +
	                  "/good.ini' -o x.rawlog --preview 12",
	              out),
	          2);
	EXPECT_EQ(run("'" + kBin + "/bims-sim' '" + d +
	                  "/good.ini' -o x.rawlog --max-frames 0",
	              out),
	          2);
}

TEST(BimsSim, ImuFromTumTrajectoryIsLabelledSynthetic)
{
	const std::string d = tmpDir("imufromtum");
	const std::string scene =
	    std::string(kSmallScene) + "\n[imu]\nnoiseless=true\n";
	simulate(d, scene, "--max-frames 60");
	std::string out;
	ASSERT_EQ(
	    run("'" + kBin + "/bims-sim' --imu-from-tum '" + d +
	            "/out_gt/groundtruth.txt' -o '" + d + "/imu.rawlog' --seed 2",
	        out),
	    0)
	    << out;
	bims::RawlogReader r(d + "/imu.rawlog");
	size_t n = 0;
	while (auto o = r.next())
	{
		EXPECT_EQ(o->sensorLabel, "IMU_SYNTH");
		n++;
	}
	EXPECT_EQ(n, 197u);  // 59/30 s at 100 Hz, both ends
	EXPECT_FALSE(bims::test::fileText(d + "/imu_gt/imu.txt").empty());
	ASSERT_EQ(run("'" + kBin + "/bims-info' '" + d + "/imu.rawlog'", out), 0)
	    << out;
	EXPECT_NE(out.find("IMU_SYNTH"), std::string::npos) << out;
}

TEST(BimsInfo, SummarisesSensorsAndRejectsBadFiles)
{
	const std::string d = tmpDir("info");
	const std::string f = simulate(d, kSmallScene, "--max-frames 31");
	std::string out;
	ASSERT_EQ(run("'" + kBin + "/bims-info' '" + f + "'", out), 0) << out;
	EXPECT_NE(out.find("observations:  133"), std::string::npos) << out;
	EXPECT_NE(out.find("30.000 Hz"), std::string::npos) << out;
	EXPECT_NE(out.find("100.000 Hz"), std::string::npos) << out;
	EXPECT_NE(out.find("duration:      1.010 s"), std::string::npos) << out;
	EXPECT_NE(out.find("depth 320x240 rgb 320x240 x31"), std::string::npos)
	    << out;
	EXPECT_EQ(run("'" + kBin + "/bims-info' '" + d + "/missing.rawlog'", out),
	          1);
	EXPECT_NE(out.find("missing.rawlog"), std::string::npos) << out;
	// Truncated file: an error naming the file, not a silent short summary.
	const std::string bytes = bims::test::fileText(f);
	std::ofstream(d + "/trunc.rawlog", std::ios::binary)
	    .write(bytes.data(), bytes.size() / 2);
	EXPECT_EQ(run("'" + kBin + "/bims-info' '" + d + "/trunc.rawlog'", out), 1)
	    << out;
	EXPECT_NE(out.find("trunc.rawlog"), std::string::npos) << out;
}

TEST(BundledSample, RegeneratingGivesTheSameRawlogAndGroundTruth)
{
#if defined(__AVX__)
	// rawlogs/ is generated by the default (baseline x86-64) build; with
	// AVX (e.g. -march=native) Eigen's vector paths sum in another order,
	// so the renderer's last bits, and the bytes, differ.
	GTEST_SKIP() << "built with AVX: the bundled sample's bytes come from a "
	                "baseline x86-64 build";
#endif
	const std::string d = tmpDir("sample");
	std::string out;
	// The command of rawlogs/README.md, run from the source tree.
	ASSERT_EQ(run("cd '" + kSrc + "' && '" + kBin +
	                  "/bims-sim' rawlogs/pendulum_slow.ini -o '" + d +
	                  "/pendulum_slow.rawlog' --seed 1 --overwrite -q",
	              out),
	          0)
	    << out;
	const std::string ref = kSrc + "/rawlogs/pendulum_slow";
	// The rawlog's content, not its gzip framing: the writer's flush per
	// frame (a killed run stays readable) changes the compressed bytes only.
	EXPECT_EQ(
	    run("bash -c \"cmp <(gzip -dc '" + d +
	            "/pendulum_slow.rawlog') <(gzip -dc '" + ref + ".rawlog')\"",
	        out),
	    0)
	    << out
	    << "rawlogs/pendulum_slow.rawlog differs from a fresh run: regenerate "
	       "it (rawlogs/README.md)";
	ASSERT_EQ(run("diff -r '" + d + "/pendulum_slow_gt' '" + ref + "_gt'", out),
	          0)
	    << out;
}

TEST(BimsSim, AFullDiskIsAnErrorAndLeavesNoRawlogUnderItsName)
{
	// every file limited to 256 KiB (SIGXFSZ ignored: writes fail with
	// EFBIG, as on a full disk); the gzip level 1 rawlog passes it
	const std::string d = tmpDir("full");
	std::string out;
	const int rc =
	    run("bash -c \"ulimit -f 256; trap '' XFSZ; exec '" + kBin +
	            "/bims-sim' '" + kSrc + "/rawlogs/pendulum_slow.ini' -o '" + d +
	            "/x.rawlog' --max-frames 40 -q\"",
	        out);
	EXPECT_EQ(rc, 1) << out;
	EXPECT_NE(out.find(d + "/x.rawlog."), std::string::npos) << out;
	EXPECT_NE(out.find(".partial: write failed"), std::string::npos) << out;
	EXPECT_FALSE(std::filesystem::exists(d + "/x.rawlog"));
	EXPECT_EQ(partialOf(d, "x.rawlog"), "");
}

TEST(BimsSim, SigintAndSigtermEndACompleteShorterSequence)
{
	for (const auto& [sig, code, name] :
	     {std::tuple{SIGINT, 130, "SIGINT"}, {SIGTERM, 143, "SIGTERM"}})
	{
		const std::string d = tmpDir(name);
		const int rc = bims::test::signalWhenExists(
		    {kBin + "/bims-sim", kSrc + "/rawlogs/pendulum_slow.ini", "-o",
		     d + "/x.rawlog", "--max-frames", "3000", "-q"},
		    d + "/log", d + "/x_gt.partial/masks/000005.png", sig);
		const std::string log = bims::test::fileText(d + "/log");
		EXPECT_EQ(rc, code) << log;
		EXPECT_NE(log.find(std::string("interrupted by ") + name + " after "),
		          std::string::npos)
		    << log;
		// the rawlog under its name, whole (a torn file throws), as long as
		// the ground truth
		bims::RawlogReader r(d + "/x.rawlog");
		size_t scans = 0;
		double tLastScan = 0, tLastImu = 0;
		while (auto o = r.next())
		{
			const double t = mrpt::Clock::toDouble(o->timestamp);
			if (IS_CLASS(*o, mrpt::obs::CObservation3DRangeScan))
				scans++, tLastScan = t;
			else
				tLastImu = t;
		}
		EXPECT_GE(scans, 5u);  // masks/000005.png was being written
		EXPECT_LT(scans, 3000u);
		EXPECT_GT(tLastImu, tLastScan);  // the IMU passes the last frame
		EXPECT_EQ(bims::loadTumTrajectory(d + "/x_gt/groundtruth.txt").size(),
		          scans);
		size_t masks = 0;
		for ([[maybe_unused]] const auto& e :
		     std::filesystem::directory_iterator(d + "/x_gt/masks"))
			masks++;
		EXPECT_EQ(masks, scans);
		EXPECT_EQ(partialOf(d, "x.rawlog"), "");
		EXPECT_FALSE(std::filesystem::exists(d + "/x_gt.partial"));
	}
}

TEST(BimsSim, AKilledRunLeavesEveryFrameWrittenSoFarReadable)
{
	// SIGKILL cannot be caught: the rawlog and its ground truth stay
	// OUT.rawlog.partial and OUT_gt.partial/, but the rawlog's gzip stream is
	// flushed after each frame and the ground truth grows line by line, so
	// both read back up to the last whole frame
	const std::string d = tmpDir("sigkill");
	const int rc = bims::test::signalWhenExists(
	    {kBin + "/bims-sim", kSrc + "/rawlogs/pendulum_slow.ini", "-o",
	     d + "/x.rawlog", "--frames", "3000", "-q"},
	    d + "/log", d + "/x_gt.partial/masks/000005.png", SIGKILL);
	ASSERT_EQ(rc, -SIGKILL) << bims::test::fileText(d + "/log");
	EXPECT_FALSE(std::filesystem::exists(d + "/x.rawlog"));
	EXPECT_FALSE(std::filesystem::exists(d + "/x_gt"));
	size_t scans = 0;
	std::string torn;  // the reader's message at a torn end, if any
	try
	{
		// OUT.rawlog.PID-TAG.partial: the killed run's own
		ASSERT_NE(partialOf(d, "x.rawlog"), "");
		bims::RawlogReader r(partialOf(d, "x.rawlog"));
		while (auto o = r.next())
			if (IS_CLASS(*o, mrpt::obs::CObservation3DRangeScan)) scans++;
	}
	catch (const bims::RawlogError& e)
	{
		torn = e.what();
	}
	if (!torn.empty())
	{
		EXPECT_NE(torn.find(partialOf(d, "x.rawlog")), std::string::npos)
		    << torn;
	}
	// frame 5 was flushed before its mask was written
	EXPECT_GE(scans, 6u) << torn;
	EXPECT_LT(scans, 3000u);
	// each ground-truth line follows its frame's flush
	const auto poses =
	    bims::loadTumTrajectory(d + "/x_gt.partial/groundtruth.txt");
	EXPECT_LE(poses.size(), scans);
	EXPECT_GE(poses.size() + 1, scans);
	const std::string imu = bims::test::fileText(d + "/x_gt.partial/imu.txt");
	ASSERT_FALSE(imu.empty());
	EXPECT_EQ(imu.back(), '\n');
	EXPECT_TRUE(std::filesystem::exists(d + "/x_gt.partial/calibration.ini"));
}

// Issue 39's reproduction: `bims-sim --overwrite` killed left the old
// rawlog beside a new ground truth. Now the earlier pair stays whole.
TEST(BimsSim, AKilledOverwriteLeavesTheEarlierRawlogAndGroundTruthTogether)
{
	const std::string d = tmpDir("sigkill_overwrite");
	std::string out;
	ASSERT_EQ(run("'" + kBin + "/bims-sim' '" + kSrc +
	                  "/rawlogs/pendulum_slow.ini' -o '" + d +
	                  "/x.rawlog' --max-frames 3 -q",
	              out),
	          0)
	    << out;
	const std::string rawlogBefore = bims::test::fileText(d + "/x.rawlog");
	const std::string gtBefore =
	    bims::test::fileText(d + "/x_gt/groundtruth.txt");
	const int rc = bims::test::signalWhenExists(
	    {kBin + "/bims-sim", kSrc + "/rawlogs/pendulum_slow.ini", "-o",
	     d + "/x.rawlog", "--frames", "3000", "-q", "--overwrite"},
	    d + "/log", d + "/x_gt.partial/masks/000005.png", SIGKILL);
	ASSERT_EQ(rc, -SIGKILL) << bims::test::fileText(d + "/log");
	EXPECT_EQ(bims::test::fileText(d + "/x.rawlog"), rawlogBefore);
	EXPECT_EQ(bims::test::fileText(d + "/x_gt/groundtruth.txt"), gtBefore);
	EXPECT_TRUE(std::filesystem::exists(d + "/x_gt/masks/000002.png"));
	EXPECT_FALSE(std::filesystem::exists(d + "/x_gt/masks/000003.png"));
	// the next run clears the killed one's folder and puts its pair in place
	ASSERT_EQ(run("'" + kBin + "/bims-sim' '" + kSrc +
	                  "/rawlogs/pendulum_slow.ini' -o '" + d +
	                  "/x.rawlog' --max-frames 4 -q --overwrite",
	              out),
	          0)
	    << out;
	EXPECT_FALSE(std::filesystem::exists(d + "/x_gt.partial"));
	// ... and the killed run's partial rawlog (its process is gone)
	EXPECT_EQ(partialOf(d, "x.rawlog"), "");
	EXPECT_EQ(bims::loadTumTrajectory(d + "/x_gt/groundtruth.txt").size(), 4u);
}

TEST(BimsSim, AnEarlierRunsGroundTruthIsRefusedUnlessOverwrite)
{
	// a shorter second run into the same OUT would leave the first run's
	// extra masks beside its own
	const std::string d = tmpDir("again");
	simulate(d, kSmallScene, "--max-frames 4");
	writeFile(d + "/out_gt/notes.txt", "mine");
	std::string out;
	const std::string again = "'" + kBin + "/bims-sim' '" + d +
	                          "/scene.ini' -o '" + d +
	                          "/out.rawlog' -q --max-frames 2";
	EXPECT_NE(run(again, out), 0) << out;
	EXPECT_NE(out.find("out_gt"), std::string::npos) << out;
	EXPECT_NE(out.find("--overwrite"), std::string::npos) << out;
	EXPECT_TRUE(std::filesystem::exists(d + "/out_gt/masks/000003.png"));
	ASSERT_EQ(run(again + " --overwrite", out), 0) << out;
	EXPECT_TRUE(std::filesystem::exists(d + "/out_gt/masks/000001.png"));
	EXPECT_FALSE(std::filesystem::exists(d + "/out_gt/masks/000002.png"));
	EXPECT_FALSE(std::filesystem::exists(d + "/out_gt/masks/000003.png"));
	EXPECT_EQ(bims::test::fileText(d + "/out_gt/notes.txt"),
	          "mine");  // not its file
}

TEST(BimsSim, TheGroundTruthLayoutNamesEveryFileARunWrites)
{
	// groundTruthLayout() is what --overwrite clears: a file the simulator
	// writes but the layout misses would survive into the next run
	const std::string d = tmpDir("layout");
	simulate(d, kSmallScene, "--max-frames 3 --preview 1");
	std::vector<std::string> written;
	for (const auto& e :
	     std::filesystem::recursive_directory_iterator(d + "/out_gt"))
		if (!e.is_directory()) written.push_back(e.path().string());
	std::sort(written.begin(), written.end());
	EXPECT_EQ(written.size(), 9u);  // 5 files, 3 masks, the manifest
	EXPECT_EQ(
	    bims::earlierOutputs(d + "/out_gt", bims::sim::groundTruthLayout()),
	    written);
	// and the manifest lists every file but itself (what the next
	// --overwrite removes)
	std::vector<std::string> listed;
	for (const auto& f : bims::manifestFiles(d + "/out_gt"))
		listed.push_back(d + "/out_gt/" + f);
	listed.push_back(d + "/out_gt/" + bims::kOutputManifest);
	std::sort(listed.begin(), listed.end());
	EXPECT_EQ(listed, written);
}
