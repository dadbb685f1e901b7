// bims-run's runExperiment on inputs that are wrong in their values, not in
// their bytes: IMU samples no sensor gives, a stray scan timestamp, a frame
// whose outputs would not be finite.
#include <bims/ego/flags.h>
#include <bims/io/frame_files.h>
#include <bims/io/json.h>
#include <bims/io/rawlog.h>
#include <bims/pipeline/run.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace bims::pipeline;

namespace
{
const std::string kSrc = BIMS_SOURCE_DIR;

std::string tmpDir(const std::string& name)
{
	return bims::test::freshTmpDir("bims_test_run_faults", name);
}

/** The first \a scans 3D scans of the bundled sample with the IMU samples
 * between them, each passed through \a edit (scan index or -1 for IMU, the
 * IMU sample's index), written to DIR/in.rawlog. */
std::string sampleWith(const std::string& dir, size_t scans,
                       const std::function<void(mrpt::obs::CObservation&,
                                                int scan, int imu)>& edit)
{
	bims::RawlogReader r(kSrc + "/rawlogs/pendulum_slow.rawlog");
	const std::string path = dir + "/in.rawlog";
	bims::RawlogWriter w(path, 0);
	int nScan = 0, nImu = 0;
	while (auto o = r.next())
	{
		if (std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(o))
		{
			if (nScan == int(scans)) break;
			edit(*o, nScan++, -1);
		}
		else
			edit(*o, -1, nImu++);
		w.write(*o);
	}
	w.close();
	return path;
}

RunSummary runOn(const std::vector<std::string>& rawlogs,
                 const std::string& out,
                 const std::string& ini = kSrc + "/config/default.ini")
{
	ExperimentConfig cfg;
	cfg.loadFromFile(ini);
	RunOptions opt;
	opt.rawlogs = rawlogs;
	opt.outDir = out;
	return runExperiment(cfg, opt);
}

std::vector<std::string> lines(const std::string& path)
{
	std::ifstream f(path);
	std::vector<std::string> v;
	for (std::string l; std::getline(f, l);)
		if (!l.empty() && l[0] != '#') v.push_back(l);
	return v;
}

void shift(mrpt::obs::CObservation& o, double s)
{
	o.timestamp =
	    mrpt::Clock::fromDouble(mrpt::Clock::toDouble(o.timestamp) + s);
}
}  // namespace

TEST(RunFaults, AbsurdImuSamplesAreRejectedCountedAndFlagged)
{
	const auto d = tmpDir("imu");
	const auto in =
	    sampleWith(d, 12,
	               [](mrpt::obs::CObservation& o, int, int imu)
	               {
		               auto* m = dynamic_cast<mrpt::obs::CObservationIMU*>(&o);
		               if (!m) return;
		               if (imu == 10) m->set(mrpt::obs::IMU_WX, 1e300);
		               if (imu == 20)
			               m->set(mrpt::obs::IMU_Z_ACC,
			                      std::numeric_limits<double>::quiet_NaN());
	               });
	const auto sum = runOn({in}, d + "/out");
	EXPECT_EQ(sum.error, "");
	EXPECT_EQ(sum.framesProcessed, 12u);
	EXPECT_EQ(sum.imuRejected, 2u);
	// every pose finite
	for (const auto& l : lines(d + "/out/trajectory.txt"))
		EXPECT_EQ(l.find("nan"), std::string::npos) << l;
	// the frames whose interval held a rejected sample carry the flag
	int flagged = 0;
	const auto csv = lines(d + "/out/frames.csv");
	for (size_t i = 1; i < csv.size(); i++)
	{
		std::stringstream ss(csv[i]);
		std::string index, t, flags;
		std::getline(ss, index, ',');
		std::getline(ss, t, ',');
		std::getline(ss, flags, ',');
		if (std::stoul(flags) & bims::ego::kFlagImuRejected) flagged++;
	}
	EXPECT_GE(flagged, 1);
	EXPECT_LE(flagged, 2);
	std::ifstream m(d + "/out/metrics.json");
	std::stringstream ms;
	ms << m.rdbuf();
	EXPECT_NE(ms.str().find("\"imu_rejected\": 2"), std::string::npos)
	    << ms.str();
}

TEST(RunFaults, AStrayScanStampSkipsThatFrameOnly)
{
	const auto d = tmpDir("stray");
	const auto in = sampleWith(d, 20,
	                           [](mrpt::obs::CObservation& o, int scan, int)
	                           {
		                           if (scan == 6) shift(o, 1e6);
	                           });
	const auto sum = runOn({in}, d + "/out");
	EXPECT_EQ(sum.error, "");
	EXPECT_EQ(sum.scansRead, 20u);
	EXPECT_EQ(sum.framesProcessed, 19u);
	EXPECT_EQ(sum.scansBadStamp, 1u);
	EXPECT_FALSE(fs::exists(d + "/out/masks/000006.png"));
	EXPECT_TRUE(fs::exists(d + "/out/masks/000019.png"));
	// the last scan stray: skipped too
	const auto in2 = sampleWith(d, 20,
	                            [](mrpt::obs::CObservation& o, int scan, int)
	                            {
		                            if (scan == 19) shift(o, 1e6);
	                            });
	const auto sum2 = runOn({in2}, d + "/out2");
	EXPECT_EQ(sum2.framesProcessed, 19u);
	EXPECT_EQ(sum2.scansBadStamp, 1u);
}

TEST(RunFaults, AJumpOfTheWholeRecordingLosesNoFrame)
{
	// from scan 6 on, every observation 1000 s later (a second recording)
	const auto d = tmpDir("jump");
	bool jumped = false;
	const auto in = sampleWith(d, 20,
	                           [&](mrpt::obs::CObservation& o, int scan, int)
	                           {
		                           if (scan == 6) jumped = true;
		                           if (jumped) shift(o, 1000);
	                           });
	const auto sum = runOn({in}, d + "/out");
	EXPECT_EQ(sum.error, "");
	EXPECT_EQ(sum.framesProcessed, 20u);
	EXPECT_EQ(sum.scansBadStamp, 0u);
}

TEST(RunFaults, AFrameWithANonFiniteOutputIsAnErrorNamingIt)
{
	FrameResult r;
	r.index = 7;
	r.t = 12.5;
	EXPECT_NO_THROW(checkFiniteOutputs(r));
	r.T_WC = mrpt::poses::CPose3D(std::nan(""), 0, 0, 0, 0, 0);
	try
	{
		checkFiniteOutputs(r);
		FAIL() << "no error";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("3D scan #7 (t 12.500000)"),
		          std::string::npos)
		    << e.what();
	}
	r.T_WC = mrpt::poses::CPose3D();
	r.movingVoxelCentres.push_back({1, std::nan(""), 0});
	EXPECT_THROW(checkFiniteOutputs(r), std::runtime_error);
}

TEST(RunFaults, MetricsJsonStaysValidWithQuotesAndControlCharacters)
{
	// the config path holds a quote, the error text (naming the truncated
	// rawlog) a control character
	const auto d = tmpDir("json") + "/a\"b\x01" + "c";
	fs::create_directories(d);
	const std::string ini = d + "/con\"fig.ini";
	fs::copy_file(kSrc + "/config/default.ini", ini);
	const std::string in = sampleWith(d, 4, [](auto&, int, int) {});
	fs::resize_file(in, fs::file_size(in) - 1000);
	const auto sum = runOn({in}, d + "/out", ini);
	ASSERT_NE(sum.error.find("\x01"), std::string::npos) << sum.error;
	std::ifstream f(d + "/out/metrics.json");
	std::stringstream s;
	s << f.rdbuf();
	const auto j = bims::Json::parse(s.str());  // throws if invalid
	EXPECT_EQ(j["config"], ini);
	EXPECT_EQ(j["error"], sum.error);
	EXPECT_EQ(j["frames_processed"], sum.framesProcessed);
}

TEST(RunFaults, ATruncatedInputKeepsEveryFrameReadWhole)
{
	// the bundled sample cut at several offsets, look-ahead on (default)
	const auto d = tmpDir("cut");
	const std::string whole = kSrc + "/rawlogs/pendulum_slow.rawlog";
	for (const size_t offset : {300000u, 777777u, 1500000u, 2345678u})
	{
		const std::string cut =
		    d + "/cut_" + std::to_string(offset) + ".rawlog";
		fs::copy_file(whole, cut);
		fs::resize_file(cut, offset);
		const auto out = d + "/out_" + std::to_string(offset);
		const auto sum = runOn({cut}, out);
		EXPECT_NE(sum.error.find(cut + ": truncated or corrupt rawlog"),
		          std::string::npos)
		    << sum.error;
		EXPECT_GT(sum.scansRead, 1u) << offset;
		EXPECT_EQ(sum.framesProcessed, sum.scansRead) << offset;
		EXPECT_EQ(lines(out + "/frames.csv").size(), sum.scansRead + 1)
		    << offset;
		EXPECT_TRUE(fs::exists(out + "/masks/" +
		                       bims::frameFileName(long(sum.scansRead) - 1)))
		    << offset;
	}
}

TEST(RunFaults, AMissingSecondInputKeepsTheFirstFilesLastFrame)
{
	const auto d = tmpDir("missing");
	const auto first = sampleWith(d, 10, [](auto&, int, int) {});
	const auto sum = runOn({first, d + "/nothing.rawlog"}, d + "/out");
	EXPECT_NE(sum.error.find("nothing.rawlog"), std::string::npos) << sum.error;
	EXPECT_EQ(sum.scansRead, 10u);
	EXPECT_EQ(sum.framesProcessed, 10u);
	EXPECT_TRUE(fs::exists(d + "/out/masks/000009.png"));
}

TEST(RunFaults, AChangedImageSizeIsAnErrorNamingFileScanAndSizes)
{
	const auto d = tmpDir("size");
	const auto in = sampleWith(
	    d, 8,
	    [](mrpt::obs::CObservation& o, int scan, int)
	    {
		    auto* s = dynamic_cast<mrpt::obs::CObservation3DRangeScan*>(&o);
		    if (!s || scan != 5) return;
		    s->rangeImage_setSize(120, 160);
		    s->intensityImage = mrpt::img::CImage(160, 120, mrpt::img::CH_RGB);
	    });
	const auto sum = runOn({in}, d + "/out");
	EXPECT_NE(sum.error.find(in +
	                         ": 3D scan #5 has a 160x120 depth image "
	                         "where the run's first had 320x240 (3D "
	                         "scan #0 of " +
	                         in + ")"),
	          std::string::npos)
	    << sum.error;
	EXPECT_EQ(sum.framesProcessed, 5u);  // those before it, all written
	EXPECT_TRUE(fs::exists(d + "/out/masks/000004.png"));
}

// Issue 55: a 1 x 1 depth image hit OpenCV's !ssize.empty() assertion (the
// keyframe alignment's pyramid), and a short wide image with colour crashed
// inside OpenCV's DIS (40 x 8: SIGSEGV). bims-run refuses the first frame
// too small for the pipeline, naming the scan, the size and the least one.
TEST(RunFaults, ImagesTooSmallForThePipelineAreAnErrorNamingTheScan)
{
	struct Case
	{
		int w, h;
		bool colour;
		const char* why;
	};
	for (const Case& c :
	     {Case{1, 1, false,
	           "depth image 1x1 is too small for the keyframe alignment, whose "
	           "pyramid halves it [anchor] coarsest_level = 2 times: it needs "
	           "at least 4 pixels per side"},
	      Case{40, 8, true,
	           "depth image 40x8 is too small for the observed flow (OpenCV's "
	           "DIS, preset fast): it needs at least 32 pixels on the shorter "
	           "side and 91 on the longer one"}})
	{
		const auto d = tmpDir("small_" + std::to_string(c.w));
		const auto in = sampleWith(
		    d, 4,
		    [&](mrpt::obs::CObservation& o, int scan, int)
		    {
			    auto* s = dynamic_cast<mrpt::obs::CObservation3DRangeScan*>(&o);
			    if (!s || scan < 0) return;
			    s->load();
			    mrpt::math::CMatrix_u16 r(c.h, c.w);
			    for (int v = 0; v < c.h; v++)
				    for (int u = 0; u < c.w; u++)
					    r(v, u) = s->rangeImage(100 + v, 100 + u);
			    s->rangeImage = r;
			    for (auto* cam : {&s->cameraParams, &s->cameraParamsIntensity})
			    {
				    cam->ncols = c.w;
				    cam->nrows = c.h;
				    cam->cx(cam->cx() - 100);
				    cam->cy(cam->cy() - 100);
			    }
			    if (c.colour)
			    {
				    mrpt::img::CImage patch;
				    s->intensityImage.extract_patch(patch, 100, 100, c.w, c.h);
				    s->intensityImage = patch;
			    }
			    else
			    {
				    s->hasIntensityImage = false;
				    s->intensityImage = mrpt::img::CImage();
			    }
		    });
		const auto sum = runOn({in}, d + "/out");
		EXPECT_NE(sum.error.find("3D scan #0 ('RGBD'): " + std::string(c.why)),
		          std::string::npos)
		    << sum.error;
		EXPECT_EQ(sum.framesProcessed, 0u);
	}
}

TEST(RunOutputs, TheLayoutNamesEveryFileARunWrites)
{
	// bims-run --overwrite clears runOutputLayout()'s files: a file a run
	// writes that the layout missed would stay from an earlier run
	const auto d = tmpDir("layout");
	std::ifstream f(kSrc + "/config/default.ini");
	std::string ini((std::istreambuf_iterator<char>(f)),
	                std::istreambuf_iterator<char>());
	ini = ini.substr(0, ini.find("[output]")) +
	      "[output]\nmoving_ply=true\nstatic_map=true\nlabelled_rawlog=true\n"
	      "flow_labels=true\n";
	std::ofstream(d + "/all.ini") << ini;
	const auto in = sampleWith(d, 4, [](auto&, int, int) {});
	const auto sum = runOn({in}, d + "/out", d + "/all.ini");
	ASSERT_EQ(sum.error, "");
	ASSERT_EQ(sum.framesProcessed, 4u);
	std::vector<std::string> written;
	for (const auto& e : fs::recursive_directory_iterator(d + "/out"))
		if (!e.is_directory()) written.push_back(e.path().string());
	std::sort(written.begin(), written.end());
	EXPECT_EQ(bims::earlierOutputs(d + "/out", runOutputLayout()), written);
	// every number of metrics.json is one metricNames() names (bims-sweep
	// --plot-metric checks against it before any run)
	const auto names = bims::pipeline::metricNames();
	std::function<void(const bims::Json&, const std::string&)> check =
	    [&](const bims::Json& j, const std::string& path)
	{
		if (j.is_object())
		{
			for (const auto& [k, v] : j.items())
				check(v, path.empty() ? k : path + "." + k);
		}
		else if (j.is_number())
		{
			EXPECT_NE(std::find(names.begin(), names.end(), path), names.end())
			    << path;
		}
	};
	const auto metrics =
	    bims::Json::parse(std::ifstream(d + "/out/metrics.json"));
	check(metrics, "");
	EXPECT_GT(metrics["stage_ms"].size(), 10u);
	// the files, the masks and flow labels of every frame (a PLY only for
	// a frame with moving voxels)
	EXPECT_GE(written.size(), 6u + 2 * 4u);
}
