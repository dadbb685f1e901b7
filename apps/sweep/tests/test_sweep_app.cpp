// bims-sweep as a program, over the bundled sample (10 frames a run): the
// runs, their table and plot, a failed run, the jobs file and --collect,
// bad input refused before any run, Ctrl-C.
#include <bims/io/json.h>
#include <bims_test/run_command.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>
#include "bims_test/text.h"

namespace fs = std::filesystem;

namespace
{
const std::string kBin = BIMS_BIN_DIR;
const std::string kSrc = BIMS_SOURCE_DIR;
const std::string kConfig = kSrc + "/config/default.ini";
const std::string kSample = kSrc + "/rawlogs/pendulum_slow.rawlog";

bims::test::CommandResult sweep(const std::string& args)
{
	return bims::test::runCommand(kBin + "/bims-sweep " + args);
}
std::string tmpDir(const std::string& name)
{
	return bims::test::freshTmpDir("bims_test_sweep_app", name);
}
std::string q(const std::string& s)
{
	return "'" + s + "'";
}
/** DIR/sweep.ini: the default config over the sample, and \a more. */
std::string writeSweep(const std::string& dir, const std::string& more)
{
	const std::string p = dir + "/sweep.ini";
	std::ofstream(p) << "[sweep]\nconfigs = " << kConfig
	                 << "\nrawlogs = " << kSample << "\n"
	                 << more;
	return p;
}
std::vector<std::string> split(const std::string& line)
{
	std::vector<std::string> out;
	std::stringstream ss(line);
	for (std::string c; std::getline(ss, c, ',');) out.push_back(c);
	if (!line.empty() && line.back() == ',') out.push_back("");
	return out;
}
/** results.csv as rows of column -> value (no quoted cells expected). */
std::vector<std::map<std::string, std::string>> readCsv(const std::string& p)
{
	std::istringstream f(bims::test::fileText(p));
	std::string line;
	std::getline(f, line);
	const auto head = split(line);
	std::vector<std::map<std::string, std::string>> rows;
	while (std::getline(f, line))
	{
		const auto cells = split(line);
		EXPECT_EQ(cells.size(), head.size()) << line;
		std::map<std::string, std::string> r;
		for (size_t i = 0; i < head.size() && i < cells.size(); i++)
			r[head[i]] = cells[i];
		rows.push_back(r);
	}
	return rows;
}
/** A PNG file's width and height from its header (0, 0 if not a PNG), and
 * whether OpenCV decodes it to that size. */
cv::Size pngSize(const std::string& p)
{
	const std::string b = bims::test::fileText(p);
	if (b.size() < 24 || b.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 ||
	    b.compare(12, 4, "IHDR") != 0)
		return {0, 0};
	auto be32 = [&](size_t at)
	{
		int v = 0;
		for (size_t i = 0; i < 4; i++)
			v = (v << 8) | static_cast<unsigned char>(b[at + i]);
		return v;
	};
	const cv::Size s(be32(16), be32(20));
	const cv::Mat img = cv::imread(p, cv::IMREAD_UNCHANGED);
	return img.size() == s ? s : cv::Size(0, 0);
}
double number(const std::string& s)
{
	size_t used = 0;
	const double v = std::stod(s, &used);
	return used == s.size() ? v : -1;
}
}  // namespace

TEST(SweepApp, TwoByTwoGridRunsFourRunsInParallelIntoOneTable)
{
	const auto d = tmpDir("two_by_two");
	const auto ini =
	    writeSweep(d,
	               "frames = 0:9\n[grid]\ngrids.voxel_size = 0.05, 0.1\n"
	               "pipeline.variant = fused, flow-only\n");
	const std::string out = d + "/out";
	const auto r = sweep(q(ini) + " -o " + q(out) + " -j 2");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("4 runs (1 configs x 4 [grid] combinations x 1 "
	                     "rawlogs)"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("bims-sweep: 2 at a time"), std::string::npos);
	for (const char* k : {"[1/4] ", "[2/4] ", "[3/4] ", "[4/4] "})
		EXPECT_NE(r.out.find(k), std::string::npos) << r.out;
	EXPECT_NE(r.out.find(": ok, "), std::string::npos) << r.out;

	const auto rows = readCsv(out + "/results.csv");
	ASSERT_EQ(rows.size(), 4u) << bims::test::fileText(out + "/results.csv");
	std::set<std::pair<std::string, std::string>> combos;
	for (const auto& row : rows)
	{
		combos.emplace(row.at("grids.voxel_size"), row.at("pipeline.variant"));
		EXPECT_EQ(row.at("status"), "ok");
		EXPECT_EQ(row.at("exit_code"), "0");
		EXPECT_EQ(row.at("frames_processed"), "10");
		EXPECT_GT(number(row.at("fps")), 0) << row.at("fps");
		EXPECT_GT(number(row.at("stage_ms.total.median")), 0);
		// the run used its derived config: bims-run says which variant
		const std::string dir = out + "/runs/" + row.at("id");
		const auto m =
		    bims::Json::parse(bims::test::fileText(dir + "/out/metrics.json"));
		EXPECT_EQ(m["variant"], row.at("pipeline.variant"));
		EXPECT_EQ(m["config"], dir + "/config.ini");
		EXPECT_NE(bims::test::fileText(dir + "/config.ini")
		              .find("voxel_size = " + row.at("grids.voxel_size")),
		          std::string::npos);
		EXPECT_NE(bims::test::fileText(dir + "/log.txt").find("outputs in"),
		          std::string::npos);
	}
	EXPECT_EQ(combos, (std::set<std::pair<std::string, std::string>>{
	                      {"0.05", "fused"},
	                      {"0.05", "flow-only"},
	                      {"0.1", "fused"},
	                      {"0.1", "flow-only"}}));
	EXPECT_EQ(rows[0].at("id"), "1_voxel_size=0.05_variant=fused");
	const std::string md = bims::test::fileText(out + "/results.md");
	for (const auto& row : rows)
		EXPECT_NE(md.find("| " + row.at("id") + " | "), std::string::npos)
		    << md;
	EXPECT_EQ(pngSize(out + "/results.png"), cv::Size(1024, 640));
}

TEST(SweepApp, AFailedRunIsReportedAndTheSweepGoesOnThenExits1)
{
	const auto d = tmpDir("failed_run");
	// a rawlog cut after a few frames: bims-run stops at the cut, exit 1
	{
		const std::string b = bims::test::fileText(kSample);
		std::ofstream(d + "/cut.rawlog", std::ios::binary)
		    << b.substr(0, 300000);
	}
	const std::string ini = d + "/sweep.ini";
	std::ofstream(ini) << "[sweep]\nconfigs = " << kConfig
	                   << "\nrawlogs = cut.rawlog " << kSample
	                   << "\nframes = 0:9\n";
	const std::string out = d + "/out";
	const auto r = sweep(q(ini) + " -o " + q(out) + " -j 2");
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_NE(r.out.find("1 of 2 runs not ok"), std::string::npos) << r.out;
	EXPECT_NE(r.out.find("1_cut: error, exit 1: "), std::string::npos) << r.out;
	const auto rows = readCsv(out + "/results.csv");
	ASSERT_EQ(rows.size(), 2u);
	EXPECT_EQ(rows[0].at("status"), "error");
	EXPECT_EQ(rows[0].at("exit_code"), "1");
	EXPECT_NE(rows[0].at("error"), "");
	EXPECT_EQ(rows[1].at("id"), "2_pendulum_slow");
	EXPECT_EQ(rows[1].at("status"), "ok");
	EXPECT_GT(number(rows[1].at("fps")), 0);
	EXPECT_NE(bims::test::fileText(out + "/results.md").find("## Runs not ok"),
	          std::string::npos);
	EXPECT_EQ(pngSize(out + "/results.png"), cv::Size(1024, 640));
}

TEST(SweepApp, JobsFileLinesRunWithBashAndCollectGathersThem)
{
	const auto d = tmpDir("jobs_file");
	const auto ini = writeSweep(
	    d, "frames = 0:4\n[grid]\npipeline.variant = fused, bottom-only\n");
	const std::string out = d + "/out", jobs = d + "/jobs.txt";
	const auto r = sweep(q(ini) + " -o " + q(out) + " --jobs-file " + q(jobs));
	ASSERT_EQ(r.code, 0) << r.out;
	std::istringstream f(bims::test::fileText(jobs));
	std::vector<std::string> lines;
	for (std::string l; std::getline(f, l);) lines.push_back(l);
	ASSERT_EQ(lines.size(), 2u) << bims::test::fileText(jobs);
	const std::string dir1 = out + "/runs/1_variant=fused";
	EXPECT_TRUE(fs::exists(dir1 + "/config.ini"));
	EXPECT_FALSE(fs::exists(dir1 + "/out"));  // nothing ran
	EXPECT_NE(lines[0].find(kBin + "/bims-run "), std::string::npos);
	EXPECT_NE(lines[0].find(" --frames 0:4 -o "), std::string::npos);
	for (size_t i = 0; i < lines.size(); i++)
	{
		const std::string job = d + "/job" + std::to_string(i) + ".sh";
		std::ofstream(job) << lines[i] << "\n";
		const auto j = bims::test::runCommand("bash " + q(job));
		EXPECT_EQ(j.code, 0) << lines[i] << "\n" << j.out;
	}
	EXPECT_NE(bims::test::fileText(dir1 + "/log.txt").find("outputs in"),
	          std::string::npos);

	const auto c = sweep("--collect " + q(out));
	ASSERT_EQ(c.code, 0) << c.out;
	const auto rows = readCsv(out + "/results.csv");
	ASSERT_EQ(rows.size(), 2u);
	EXPECT_EQ(rows[1].at("pipeline.variant"), "bottom-only");
	for (const auto& row : rows)
	{
		EXPECT_EQ(row.at("status"), "ok");
		EXPECT_EQ(row.at("exit_code"), "");  // not run by the sweep
		EXPECT_EQ(row.at("frames_processed"), "5");
		EXPECT_GT(number(row.at("fps")), 0);
	}
	EXPECT_EQ(pngSize(out + "/results.png"), cv::Size(1024, 640));
	// another metric on the vertical axis; an unknown one is named
	EXPECT_EQ(sweep("--collect " + q(out) + " --plot-metric wall_seconds").code,
	          0);
	const auto bad = sweep("--collect " + q(out) + " --plot-metric fsp");
	EXPECT_EQ(bad.code, 1);
	EXPECT_NE(bad.out.find("no run has the metric 'fsp'"), std::string::npos)
	    << bad.out;
}

TEST(SweepApp, RunsWithGroundTruthAreScoredIntoTheResults)
{
	const auto d = tmpDir("truth");
	// the sample's pendulum_slow_gt/: masks and trajectory
	const auto ini = writeSweep(d,
	                            "frames = 0:4\n[set]\npipeline.variant = "
	                            "fused\n[truth]\nmasks = auto\ntrajectory = "
	                            "auto\n");
	const std::string out = d + "/out";
	// a score is a metric to plot when the runs are scored, not otherwise
	EXPECT_EQ(sweep(q(ini) + " -o " + q(out) +
	                " --dry-run --plot-metric masks.total.f1")
	              .code,
	          0);
	fs::create_directories(d + "/u");
	const auto unscored = writeSweep(d + "/u", "frames = 0:4\n");
	const auto refused = sweep(q(unscored) + " -o " + q(d + "/u/out") +
	                           " --dry-run --plot-metric masks.total.f1");
	EXPECT_EQ(refused.code, 2) << refused.out;
	EXPECT_EQ(refused.out.find("masks.*"), std::string::npos) << refused.out;
	const auto r = sweep(q(ini) + " -o " + q(out) + " -q");
	ASSERT_EQ(r.code, 0) << r.out;
	auto rows = readCsv(out + "/results.csv");
	ASSERT_EQ(rows.size(), 1u);
	const auto row = rows[0];
	EXPECT_EQ(row.at("id"), "1");  // a constant is in no run id
	EXPECT_EQ(row.at("pipeline.variant"), "fused");
	EXPECT_EQ(row.at("status"), "ok");
	const double f1 = number(row.at("masks.total.f1"));
	EXPECT_GT(f1, 0) << row.at("masks.total.f1");  // 5 frames: low
	EXPECT_LE(f1, 1.0);
	EXPECT_GE(number(row.at("masks.total.precision")), 0);
	const double ate = number(row.at("traj.ate.error_m.rmse"));
	EXPECT_GE(ate, 0) << row.at("traj.ate.error_m.rmse");
	EXPECT_LT(ate, 0.1);
	const std::string dir = out + "/runs/1";
	EXPECT_NE(bims::test::fileText(dir + "/eval.txt").find("total precision"),
	          std::string::npos);
	EXPECT_GT(pngSize(dir + "/traj.png").width, 0);
	const std::string md = bims::test::fileText(out + "/results.md");
	EXPECT_NE(md.find("Every run: pipeline.variant=fused."), std::string::npos)
	    << md;
	EXPECT_NE(md.find("masks.total.f1"), std::string::npos) << md;

	// --collect scores the runs done elsewhere (no masks.json yet)
	fs::remove(dir + "/masks.json");
	fs::remove(dir + "/traj.json");
	ASSERT_EQ(
	    sweep("--collect " + q(out) + " --plot-metric masks.total.f1").code, 0);
	rows = readCsv(out + "/results.csv");
	EXPECT_EQ(rows[0].at("masks.total.f1"), row.at("masks.total.f1"));
	EXPECT_EQ(rows[0].at("traj.ate.error_m.rmse"),
	          row.at("traj.ate.error_m.rmse"));

	// labels that cannot be scored: the run is "not scored", exit 1
	fs::create_directories(d + "/nolabels");
	const auto bad = writeSweep(d, "frames = 0:4\n[truth]\nmasks = nolabels\n");
	const auto b = sweep(q(bad) + " -o " + q(d + "/bad") + " -q");
	EXPECT_EQ(b.code, 1) << b.out;
	EXPECT_NE(b.out.find("1: not scored, exit 0: bims-eval masks: "),
	          std::string::npos)
	    << b.out;
	EXPECT_EQ(readCsv(d + "/bad/results.csv")[0].at("status"), "not scored");
}

TEST(SweepApp, SlurmSubmitsOneArrayJobWhoseTaskIRunsLineI)
{
	const auto d = tmpDir("slurm_stub");
	// a stand-in sbatch: records its arguments, answers a job id
	fs::create_directories(d + "/bin");
	std::ofstream(d + "/bin/sbatch")
	    << "#!/bin/sh\nprintf '%s\\n' \"$@\" > " << q(d + "/args.txt")
	    << "\necho '4242;cluster'\n";
	fs::permissions(d + "/bin/sbatch", fs::perms::owner_all);
	const auto ini = writeSweep(
	    d, "frames = 0:2\n[grid]\npipeline.variant = fused, bottom-only\n");
	const std::string out = d + "/out";
	const std::string path = "PATH=" + q(d + "/bin") + ":\"$PATH\" ";
	const auto r = bims::test::runCommand(
	    path + kBin + "/bims-sweep " + q(ini) + " -o " + q(out) +
	    " --slurm --sbatch '--partition=p --time=5'");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_NE(r.out.find("2 runs submitted as Slurm array job 4242"),
	          std::string::npos)
	    << r.out;
	const std::string args = bims::test::fileText(d + "/args.txt");
	for (const std::string& a : std::vector<std::string>{
	         "--parsable\n", "--array=1-2\n", "--partition=p\n", "--time=5\n",
	         "--output=" + out + "/slurm/%A_%a.out\n", out + "/slurm.sh\n"})
		EXPECT_NE(args.find(a), std::string::npos) << a << " in " << args;
	EXPECT_EQ(bims::test::fileText(out + "/jobs.txt").find(kBin + "/bims-run"),
	          0u);
	// task 2 runs the second line only
	const auto t = bims::test::runCommand("SLURM_ARRAY_TASK_ID=2 bash " +
	                                      q(out + "/slurm.sh"));
	EXPECT_EQ(t.code, 0) << t.out;
	EXPECT_FALSE(fs::exists(out + "/runs/1_variant=fused/out/metrics.json"));
	EXPECT_TRUE(
	    fs::exists(out + "/runs/2_variant=bottom-only/out/metrics.json"));

	// sbatch failing, or not there: an error naming it
	std::ofstream(d + "/bin/sbatch")
	    << "#!/bin/sh\necho 'sbatch: error: invalid partition' >&2\nexit 1\n";
	const auto f =
	    bims::test::runCommand(path + kBin + "/bims-sweep " + q(ini) + " -o " +
	                           q(out) + " --overwrite --slurm");
	EXPECT_EQ(f.code, 1) << f.out;
	EXPECT_NE(f.out.find("sbatch failed (exit code 1): sbatch: error: "
	                     "invalid partition"),
	          std::string::npos)
	    << f.out;
	EXPECT_EQ(sweep(q(ini) + " -o " + q(out) + " --sbatch x").code, 2);
}

TEST(SweepApp, BadInputIsAnErrorNamingFileAndKeyBeforeAnyRun)
{
	const auto d = tmpDir("bad_input");
	const std::string out = d + "/out";
	const struct
	{
		std::string more;
		std::string expect;
	} cases[] = {
	    {"frame = 0:9\n", "sweep.ini: [sweep] frame: unknown key"},
	    {"[grid]\ngrids.voxl_size = 0.05\n",
	     "sweep.ini: [grid] grids.voxl_size = 0.05: on " + kConfig +
	         ": [grids] voxl_size: unknown key"},
	    {"[grid]\npipeline.variant = fused, fsued\n",
	     "sweep.ini: [grid] pipeline.variant = fsued: on " + kConfig +
	         ": [pipeline] variant: 'fsued' is not one of"},
	    {"[grid]\ngrids.voxel_size = 0.05, -1\n",
	     "sweep.ini: [grid] grids.voxel_size = -1: on " + kConfig +
	         ": [grids] voxel_size: value -1 out of range"},
	};
	for (const auto& c : cases)
	{
		const auto ini = writeSweep(d, c.more);
		const auto r = sweep(q(ini) + " -o " + q(out));
		EXPECT_EQ(r.code, 1) << r.out;
		EXPECT_NE(r.out.find("bims-sweep: error: " + d + "/" + c.expect),
		          std::string::npos)
		    << "expected '" << c.expect << "' in: " << r.out;
		EXPECT_FALSE(fs::exists(out)) << c.more;
	}
	{
		const std::string ini = d + "/sweep.ini";
		std::ofstream(ini) << "[sweep]\nconfigs = " << kConfig
		                   << "\nrawlogs = missing.rawlog\n";
		const auto r = sweep(q(ini) + " -o " + q(out));
		EXPECT_EQ(r.code, 1) << r.out;
		EXPECT_NE(r.out.find("[sweep] rawlogs: 'missing.rawlog': no such file"),
		          std::string::npos)
		    << r.out;
	}
	const auto ini = writeSweep(d, "");
	// an output folder holding an input
	const auto alias = sweep(q(ini) + " -o " + q(d));
	EXPECT_EQ(alias.code, 2) << alias.out;
	EXPECT_NE(alias.out.find("contains the input " + ini), std::string::npos)
	    << alias.out;
	EXPECT_FALSE(fs::exists(d + "/runs"));
	EXPECT_EQ(sweep(q(ini)).code, 2);  // no -o
	EXPECT_EQ(sweep(q(ini) + " -o " + q(out) + " -j -1").code, 2);
	// Issue 39: --plot-metric nope passed --dry-run and failed after every
	// run; it is refused first, listing the names metrics.json has
	for (const char* more : {" --dry-run", ""})
	{
		const auto metric =
		    sweep(q(ini) + " -o " + q(out) + " --plot-metric nope" + more);
		EXPECT_EQ(metric.code, 2) << metric.out;
		EXPECT_NE(metric.out.find("--plot-metric nope: not a number bims-run "
		                          "writes in metrics.json; one of: "
		                          "frames_processed, "),
		          std::string::npos)
		    << metric.out;
		for (const char* name :
		     {", fps,", "frames_flagged_by.{imu_missing,imu_gap,",
		      "stage_ms.{read,read_cpu,wait_input,input,",
		      "}.{median,p95,mean,n}"})
			EXPECT_NE(metric.out.find(name), std::string::npos)
			    << name << " in " << metric.out;
		EXPECT_FALSE(fs::exists(out));
	}
	// --dry-run: the runs listed, nothing written
	const auto dry = sweep(q(ini) + " -o " + q(out) + " --dry-run");
	EXPECT_EQ(dry.code, 0) << dry.out;
	EXPECT_NE(dry.out.find("1: " + kBin + "/bims-run "), std::string::npos)
	    << dry.out;
	EXPECT_FALSE(fs::exists(out));
}

TEST(SweepApp, SigintStopsLaunchingAndInterruptsTheRunningRunCleanly)
{
	const auto d = tmpDir("sigint");
	// whole sample: the first run is still going when the signal comes
	const auto ini = writeSweep(d, "[grid]\ngrids.voxel_size = 0.05, 0.1\n");
	const std::string out = d + "/out";
	const int code = bims::test::signalWhenExists(
	    {kBin + "/bims-sweep", ini, "-o", out, "-j", "1"}, d + "/log.txt",
	    out + "/runs/1_voxel_size=0.05/out/trajectory.txt", SIGINT);
	const std::string log = bims::test::fileText(d + "/log.txt");
	EXPECT_EQ(code, 128 + SIGINT) << log;
	EXPECT_NE(log.find("interrupted: 1 of 2 runs not started"),
	          std::string::npos)
	    << log;
	const auto m = bims::Json::parse(
	    bims::test::fileText(out + "/runs/1_voxel_size=0.05/out/metrics.json"));
	EXPECT_EQ(m["status"], "interrupted");
	EXPECT_LT(m["frames_processed"].get<int>(), 150);
	EXPECT_FALSE(fs::exists(out + "/runs/2_voxel_size=0.1/log.txt"));
	const auto rows = readCsv(out + "/results.csv");
	ASSERT_EQ(rows.size(), 2u);
	EXPECT_EQ(rows[0].at("status"), "interrupted");
	EXPECT_EQ(rows[0].at("exit_code"), std::to_string(128 + SIGINT));
	EXPECT_EQ(rows[1].at("status"), "not run");
}
