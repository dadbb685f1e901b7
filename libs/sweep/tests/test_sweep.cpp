// bims-sweep's parts: SWEEP.ini and the plan, the derived configs, the
// child processes, the results table and plot (the program itself:
// apps/sweep/tests).
#include <bims/common/config.h>
#include <bims/pipeline/config.h>
#include <bims/sweep/plan.h>
#include <bims/sweep/processes.h>
#include <bims/sweep/results.h>
#include <bims_test/error_of.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <thread>
#include "bims_test/text.h"

using bims::test::errorOf;

namespace fs = std::filesystem;
namespace sw = bims::sweep;

namespace
{
const std::string kDefault =
    std::string(BIMS_SOURCE_DIR) + "/config/default.ini";

std::string tmpDir(const std::string& name)
{
	return bims::test::freshTmpDir("bims_test_sweep", name);
}
void put(const std::string& path, const std::string& text)
{
	fs::create_directories(fs::path(path).parent_path());
	std::ofstream(path) << text;
}
/** A folder with a.ini, sub/b.ini (copies of default.ini) and two
 * stand-in rawlogs x.rawlog, y.rawlog (planning only checks they exist);
 * SWEEP.ini there with \a body. */
std::string sweepFolder(const std::string& name, const std::string& body)
{
	const auto d = tmpDir(name);
	fs::copy_file(kDefault, d + "/a.ini");
	fs::create_directories(d + "/sub");
	fs::copy_file(kDefault, d + "/sub/b.ini");
	put(d + "/x.rawlog", "x");
	put(d + "/y.rawlog", "y");
	put(d + "/sweep.ini", body);
	return d;
}
std::string planError(const std::string& d)
{
	return errorOf(
	    [&] { sw::SweepPlan::make(sw::SweepSpec::load(d + "/sweep.ini")); });
}
}  // namespace

TEST(SweepPlan, IsTheProductOfConfigsGridAndRawlogsWithReadableIds)
{
	const auto d = sweepFolder(
	    "product",
	    "[sweep]\nconfigs = a.ini sub/b.ini\nrawlogs = x.rawlog y.rawlog\n"
	    "frames = 0:9\nname = demo\n[grid]\npipeline.variant = fused, "
	    "flow-only\ngrids.voxel_size = 0.05,0.1 , 0.2\n");
	const auto spec = sw::SweepSpec::load(d + "/sweep.ini");
	EXPECT_EQ(spec.name, "demo");
	ASSERT_EQ(spec.configs.size(), 2u);
	EXPECT_EQ(spec.configs[1].written, "sub/b.ini");
	EXPECT_EQ(spec.configs[1].path, fs::path(d + "/sub/b.ini").string());
	const auto plan = sw::SweepPlan::make(spec);
	ASSERT_EQ(plan.runs.size(), 2u * 6u * 2u);
	EXPECT_EQ(plan.gridKeys, (std::vector<std::string>{"grids.voxel_size",
	                                                   "pipeline.variant"}));
	// configs outer, rawlogs inner, the last grid key fastest
	EXPECT_EQ(plan.runs[0].id, "01_a_voxel_size=0.05_variant=fused_x");
	EXPECT_EQ(plan.runs[1].id, "02_a_voxel_size=0.05_variant=fused_y");
	EXPECT_EQ(plan.runs[2].id, "03_a_voxel_size=0.05_variant=flow-only_x");
	EXPECT_EQ(plan.runs[23].id, "24_b_voxel_size=0.2_variant=flow-only_y");
	std::set<std::string> ids;
	for (const auto& r : plan.runs) ids.insert(r.id);
	EXPECT_EQ(ids.size(), plan.runs.size());

	// the derived config: the base with the overrides, comments kept
	const auto& r = plan.runs[21];  // b, 0.2, fused, y
	EXPECT_EQ(r.overrides[0].second, "0.2");
	EXPECT_EQ(r.overrides[1].second, "fused");
	EXPECT_EQ(r.rawlog.written, "y.rawlog");
	mrpt::config::CConfigFileMemory mem(r.configText);
	EXPECT_EQ(mem.read_string("grids", "voxel_size", ""), "0.2");
	EXPECT_EQ(mem.read_string("pipeline", "variant", ""), "fused");
	EXPECT_EQ(mem.read_string("flow", "method", ""), "dis");
	EXPECT_NE(r.configText.find("# bims experiment"), std::string::npos);
	bims::pipeline::ExperimentConfig cfg;
	cfg.loadFromConfigFile(mem);
	EXPECT_DOUBLE_EQ(cfg.grids.voxel_size, 0.2);
	EXPECT_EQ(cfg.pipeline.variant, bims::pipeline::Variant::Fused);
}

TEST(SweepSpec, UnknownSectionsKeysAndMissingFilesNameFileAndKey)
{
	const std::string ok = "configs = a.ini\nrawlogs = x.rawlog\n";
	const struct
	{
		std::string body, expect;
	} cases[] = {
	    {"[sweep]\n" + ok + "confgs = a.ini\n", "[sweep] confgs: unknown key"},
	    {"[sweep]\n" + ok + "[grids]\nvoxel_size = 1\n",
	     "[grids]: unknown section"},
	    {"[sweep]\nconfigs = a.ini nope.ini\nrawlogs = x.rawlog\n",
	     "[sweep] configs: 'nope.ini': no such file"},
	    {"[sweep]\nconfigs = a.ini\nrawlogs = x.rawlog gone.rawlog\n",
	     "[sweep] rawlogs: 'gone.rawlog': no such file"},
	    {"[sweep]\nconfigs = a.ini\nrawlogs = x.rawlog x.rawlog\n",
	     "[sweep] rawlogs: 'x.rawlog' listed twice"},
	    {"[sweep]\nrawlogs = x.rawlog\n", "[sweep] configs: required"},
	    {"[sweep]\n" + ok + "frames = 9:0\n", "[sweep] frames: "},
	    {"[sweep]\n" + ok + "[grid]\nvoxel_size = 0.1\n",
	     "[grid] voxel_size: not an experiment key"},
	    {"[sweep]\n" + ok + "[grid]\ngrids.voxel_size = 0.1,,0.2\n",
	     "[grid] grids.voxel_size: '0.1,,0.2': an empty item"},
	    {"[sweep]\n" + ok + "[grid]\ngrids.voxel_size = 0.1, 0.1\n",
	     "[grid] grids.voxel_size: value '0.1' given twice"},
	    {"[sweep]\n" + ok + "configs = a.ini\n", "given twice"},
	};
	for (const auto& c : cases)
	{
		const auto d = sweepFolder("spec_errors", c.body);
		const std::string e = planError(d);
		EXPECT_NE(e.find(d + "/sweep.ini"), std::string::npos) << e;
		EXPECT_NE(e.find(c.expect), std::string::npos)
		    << "expected '" << c.expect << "' in: " << e;
	}
}

TEST(SweepPlan, OverridesAreCheckedByBimsRunsLoaderNamingKeyValueAndConfig)
{
	const std::string head =
	    "[sweep]\nconfigs = a.ini sub/b.ini\nrawlogs = x.rawlog\n[grid]\n";
	const struct
	{
		std::string grid, expect;
	} cases[] = {
	    {"grids.voxl_size = 0.05",
	     "[grid] grids.voxl_size = 0.05: on a.ini: "
	     "[grids] voxl_size: unknown key"},
	    {"grids.voxel_size = 0.05, abc",
	     "[grid] grids.voxel_size = abc: on a.ini: [grids] voxel_size: 'abc' "
	     "is not a finite number"},
	    {"grids.voxel_size = 0.05, 100",
	     "[grid] grids.voxel_size = 100: on a.ini: [grids] voxel_size: "
	     "value 100 out of range"},
	    {"foo.bar = 1", "[grid] foo.bar = 1: on a.ini: [foo]: unknown section"},
	    {"pipeline.variant = fused, fast",
	     "[grid] pipeline.variant = fast: on a.ini: [pipeline] variant: "
	     "'fast' is not one of"},
	};
	for (const auto& c : cases)
	{
		const auto d = sweepFolder("override_errors", head + c.grid + "\n");
		const std::string e = planError(d);
		EXPECT_EQ(e.rfind(d + "/sweep.ini: ", 0), 0u) << e;
		EXPECT_NE(e.find(c.expect), std::string::npos)
		    << "expected '" << c.expect << "' in: " << e;
		EXPECT_EQ(e.find("<memory>"), std::string::npos) << e;
	}
	// a config that is bad by itself is named as itself
	const auto d = sweepFolder("bad_base", head + "grids.voxel_size = 0.1\n");
	std::string b = bims::test::fileText(kDefault);
	b.insert(b.find("[grids]\n") + 8, "typo = 1\n");
	put(d + "/sub/b.ini", b);
	const std::string e = planError(d);
	EXPECT_EQ(e.rfind(d + "/sub/b.ini: [grids] typo: unknown key", 0), 0u) << e;
}

TEST(SweepPlan, RoundTripsThroughSweepJsonAndRunFolders)
{
	const auto d = sweepFolder("json",
	                           "[sweep]\nconfigs = a.ini\nrawlogs = x.rawlog "
	                           "y.rawlog\nframes = 2:5\n[grid]\n"
	                           "grids.voxel_size = 0.05, 0.1\n");
	const auto plan =
	    sw::SweepPlan::make(sw::SweepSpec::load(d + "/sweep.ini"));
	const std::string out = d + "/out";
	// a metrics.json of an earlier plan is not this plan's result
	put(sw::runOutDir(out, plan.runs[0].id) + "/metrics.json", "{}");
	sw::writePlan(plan, out);
	EXPECT_FALSE(
	    fs::exists(sw::runOutDir(out, plan.runs[0].id) + "/metrics.json"));
	for (const auto& r : plan.runs)
		EXPECT_EQ(bims::test::fileText(sw::runDir(out, r.id) + "/config.ini"),
		          r.configText);
	const auto back = sw::SweepPlan::readJson(out + "/sweep.json");
	EXPECT_EQ(back.name, "sweep");
	EXPECT_EQ(back.frames, "2:5");
	EXPECT_EQ(back.gridKeys, plan.gridKeys);
	ASSERT_EQ(back.runs.size(), 4u);
	for (size_t i = 0; i < 4; i++)
	{
		EXPECT_EQ(back.runs[i].id, plan.runs[i].id);
		EXPECT_EQ(back.runs[i].overrides, plan.runs[i].overrides);
		EXPECT_EQ(back.runs[i].rawlog.path, plan.runs[i].rawlog.path);
	}
	const auto argv = sw::runCommand("/x/bims-run", plan, plan.runs[3], out);
	const std::string dir = sw::runDir(out, plan.runs[3].id);
	EXPECT_EQ(argv,
	          (std::vector<std::string>{
	              "/x/bims-run", dir + "/config.ini", d + "/y.rawlog",
	              "--frames", "2:5", "-o", dir + "/out", "--overwrite", "-q"}));
	EXPECT_EQ(sw::shellLine({"/a b/x", "it's", "-q", "k=v", ""}),
	          "'/a b/x' 'it'\\''s' -q k=v ''");
	EXPECT_NE(errorOf([&] { sw::SweepPlan::readJson(d + "/a.ini"); })
	              .find(d + "/a.ini: not a bims-sweep plan"),
	          std::string::npos);
}

TEST(SweepProcesses, AtMostNRunAtOnceEachWithItsLogAndExitCode)
{
	const auto d = tmpDir("processes");
	const std::string trace = d + "/trace";
	std::vector<sw::Job> jobs;
	for (int i = 0; i < 4; i++)
		jobs.push_back({{"/bin/sh", "-c",
		                 "echo start >> " + trace + "; echo job " +
		                     std::to_string(i) + "; sleep 0.3; echo end >> " +
		                     trace + "; exit " + std::to_string(i)},
		                d + "/log" + std::to_string(i) + ".txt"});
	jobs.push_back({{d + "/no_such_program"}, d + "/log4.txt"});
	std::vector<size_t> order;
	sw::PoolOptions opt;
	opt.workers = 2;
	opt.onDone = [&](size_t i, const sw::JobOutcome&) { order.push_back(i); };
	const auto out = sw::runJobs(jobs, opt);
	ASSERT_EQ(out.size(), 5u);
	for (int i = 0; i < 4; i++)
	{
		EXPECT_TRUE(out[i].started);
		EXPECT_EQ(out[i].exitCode, i);
		EXPECT_GE(out[i].seconds, 0.25);
		EXPECT_EQ(bims::test::fileText(d + "/log" + std::to_string(i) + ".txt"),
		          "job " + std::to_string(i) + "\n");
	}
	EXPECT_EQ(out[4].exitCode, 127);
	EXPECT_NE(bims::test::fileText(d + "/log4.txt")
	              .find("cannot execute " + d + "/no_such_program"),
	          std::string::npos);
	EXPECT_EQ(order.size(), 5u);
	// two at a time: both first jobs started before either ended, never a
	// third at once
	int now = 0, most = 0;
	std::istringstream t(bims::test::fileText(trace));
	for (std::string w; t >> w;)
		most = std::max(most, now += w == "start" ? 1 : -1);
	EXPECT_EQ(most, 2) << bims::test::fileText(trace);
}

TEST(SweepProcesses, StopLaunchesNoMoreAndPassesTheSignalOnOnce)
{
	const auto d = tmpDir("stop");
	std::vector<sw::Job> jobs;
	for (int i = 0; i < 3; i++)
		jobs.push_back(
		    {{"/bin/sh", "-c",
		      "trap 'echo got INT; kill $!; exit 9' INT; echo ready > " + d +
		          "/ready; sleep 20 & wait"},
		     d + "/log" + std::to_string(i) + ".txt"});
	std::atomic<bool> stop{false};
	std::thread t(
	    [&]
	    {
		    for (int i = 0; i < 500 && !fs::exists(d + "/ready"); i++)
			    std::this_thread::sleep_for(std::chrono::milliseconds(10));
		    stop = true;
	    });
	sw::PoolOptions opt;
	opt.stop = &stop;
	opt.stopSignal = [] { return SIGINT; };
	const auto start = std::chrono::steady_clock::now();
	const auto out = sw::runJobs(jobs, opt);
	t.join();
	EXPECT_LT(
	    std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
	        .count(),
	    15.0);
	EXPECT_TRUE(out[0].started);
	EXPECT_EQ(out[0].exitCode, 9);
	EXPECT_EQ(bims::test::fileText(d + "/log0.txt"), "got INT\n");
	EXPECT_FALSE(out[1].started);
	EXPECT_FALSE(out[2].started);
	EXPECT_EQ(out[2].exitCode, -1);
	EXPECT_FALSE(fs::exists(d + "/log1.txt"));
}

namespace
{
/** Two grid keys, one rawlog; run 2 failed; \a dir holds their folders. */
sw::ResultTable table(const std::string& dir)
{
	sw::SweepPlan p;
	p.name = "t";
	p.sweepFile = "s.ini";
	p.gridKeys = {"grids.voxel_size", "pipeline.variant"};
	for (int i = 0; i < 4; i++)
	{
		sw::RunSpec r;
		r.id = std::to_string(i + 1);
		r.config = {"a.ini", dir + "/a.ini"};
		r.rawlog = {"x.rawlog", dir + "/x.rawlog"};
		r.overrides = {{"grids.voxel_size", i < 2 ? "0.05" : "0.1"},
		               {"pipeline.variant", i % 2 ? "flow-only" : "fused"}};
		p.runs.push_back(r);
	}
	sw::ResultTable t{p, {}};
	for (size_t i = 0; i < 4; i++)
	{
		const std::string rd = sw::runOutDir(dir, p.runs[i].id);
		fs::create_directories(rd);
		const bool bad = i == 1;
		put(rd + "/metrics.json",
		    std::string("{\"status\": \"") + (bad ? "error" : "ok") +
		        "\", \"variant\": \"fused\", \"frames_processed\": 10, "
		        "\"fps\": " +
		        std::to_string(10.5 + i) +
		        ", \"data_seconds\": null, \"stage_ms\": {\"total\": "
		        "{\"median\": 12.25, \"n\": 10}}, \"error\": \"" +
		        (bad ? "x.rawlog: entry 3: \\\"truncated\\\", at 7" : "") +
		        "\"}");
		sw::JobOutcome o;
		o.started = true;
		o.exitCode = bad ? 1 : 0;
		o.seconds = 2.5;
		t.rows.push_back(sw::collectRun(p.runs[i], dir, &o));
	}
	return t;
}
}  // namespace

TEST(SweepResults, CollectReadsMetricsJsonAndTheOtherJsonFilesOfTheRun)
{
	const auto d = tmpDir("collect");
	auto t = table(d);
	put(sw::runDir(d, "3") + "/ate.json",
	    "{\"ate\": {\"pairs\": 10, \"error_m\": {\"rmse\": 0.0125}}, "
	    "\"frames\": [1, 2]}");
	const auto r = sw::collectRun(t.plan.runs[2], d);
	EXPECT_EQ(r.status, "ok");
	EXPECT_FALSE(r.exitCode.has_value());
	EXPECT_TRUE(r.ok());
	EXPECT_DOUBLE_EQ(r.metric("fps"), 12.5);
	EXPECT_DOUBLE_EQ(r.metric("stage_ms.total.median"), 12.25);
	EXPECT_DOUBLE_EQ(r.metric("ate.ate.error_m.rmse"), 0.0125);
	EXPECT_TRUE(std::isnan(r.metric("data_seconds")));
	EXPECT_TRUE(std::isnan(r.metric("variant")));
	EXPECT_FALSE(t.rows[1].ok());
	EXPECT_EQ(t.rows[1].status, "error");

	sw::RunSpec absent = t.plan.runs[0];
	absent.id = "absent";
	EXPECT_EQ(sw::collectRun(absent, d).status, "missing");
	sw::JobOutcome notRun;
	EXPECT_EQ(sw::collectRun(absent, d, &notRun).status, "not run");
	sw::JobOutcome died;
	died.started = true;
	died.exitCode = 134;
	const auto f = sw::collectRun(absent, d, &died);
	EXPECT_EQ(f.status, "failed");
	EXPECT_EQ(*f.exitCode, 134);
	EXPECT_FALSE(f.ok());
	// an exit code that is not 0 fails an "ok" run too
	sw::JobOutcome odd;
	odd.started = true;
	odd.exitCode = 3;
	EXPECT_FALSE(sw::collectRun(t.plan.runs[0], d, &odd).ok());
}

TEST(SweepResults, CsvAndMarkdownHoldEveryRunWithItsOverridesAndErrors)
{
	const auto d = tmpDir("tables");
	const auto t = table(d);
	const std::string csv = sw::csvText(t);
	std::istringstream lines(csv);
	std::string head, row;
	std::getline(lines, head);
	EXPECT_EQ(head,
	          "id,config,rawlog,grids.voxel_size,pipeline.variant,status,"
	          "exit_code,run_seconds,frames_processed,fps,data_seconds,"
	          "stage_ms.total.median,stage_ms.total.n,error");
	std::getline(lines, row);
	EXPECT_EQ(row, "1,a.ini,x.rawlog,0.05,fused,ok,0,2.5,10,10.5,,12.25,10,");
	std::getline(lines, row);
	EXPECT_EQ(row,
	          "2,a.ini,x.rawlog,0.05,flow-only,error,1,2.5,10,11.5,,12.25,10,"
	          "\"x.rawlog: entry 3: \"\"truncated\"\", at 7\"");
	size_t n = 2;
	while (std::getline(lines, row)) n++;
	EXPECT_EQ(n, 4u);

	const std::string md = sw::markdownText(t, "stage_ms.total.n");
	EXPECT_NE(md.find("| id | config | rawlog | grids.voxel_size | "
	                  "pipeline.variant | status | exit | s | frames_processed "
	                  "| fps | stage_ms.total.median | stage_ms.total.n |"),
	          std::string::npos)
	    << md;
	EXPECT_NE(md.find("| 4 | a.ini | x.rawlog | 0.1 | flow-only | ok | 0 | "
	                  "2.5 | 10 | 13.5 | 12.25 | 10 |"),
	          std::string::npos)
	    << md;
	EXPECT_NE(md.find("- 2: error, exit 1: x.rawlog: entry 3"),
	          std::string::npos)
	    << md;
}

// A score no run has a value of (NaN in every run: e.g. the figures of the
// frames without moving labels when every frame has some) stays out of
// results.md; it is still in results.csv.
TEST(SweepResults, MarkdownLeavesOutScoresNoRunHas)
{
	const auto d = tmpDir("nan_scores");
	auto t = table(d);
	for (auto& r : t.rows)
	{
		r.metrics.push_back({"masks.total.f1", 0.9});
		r.metrics.push_back({"masks.total_nothing_moving.f1", NAN});
	}
	const std::string md = sw::markdownText(t, "fps");
	EXPECT_NE(md.find("| masks.total.f1 |"), std::string::npos) << md;
	EXPECT_EQ(md.find("total_nothing_moving"), std::string::npos) << md;
	EXPECT_NE(sw::csvText(t).find("masks.total_nothing_moving.f1"),
	          std::string::npos);
	// one run with a value: the column stays
	t.rows[2].metrics.back().second = 0.5;
	EXPECT_NE(sw::markdownText(t, "fps").find("masks.total_nothing_moving.f1"),
	          std::string::npos);
}

TEST(SweepResults, PlotGroupsRunsByOverridesAndRefusesAnUnknownMetric)
{
	const auto d = tmpDir("plot");
	const auto t = table(d);
	const cv::Mat img = sw::plotResults(t, "fps");
	EXPECT_EQ(img.cols, 1024);
	EXPECT_EQ(img.rows, 640);
	EXPECT_EQ(img.type(), CV_8UC3);
	const std::string e = errorOf([&] { sw::plotResults(t, "fsp"); });
	EXPECT_NE(e.find("no run has the metric 'fsp'"), std::string::npos) << e;
	EXPECT_NE(e.find("fps"), std::string::npos) << e;
}

TEST(SweepPlan, TheBundledExamplePlansFourRuns)
{
	const auto plan = sw::SweepPlan::make(sw::SweepSpec::load(
	    std::string(BIMS_SOURCE_DIR) + "/config/sweep_example.ini"));
	EXPECT_EQ(plan.name, "sample voxel size x variant");
	EXPECT_EQ(plan.frames, "0:29");
	ASSERT_EQ(plan.runs.size(), 4u);
	EXPECT_EQ(plan.runs[3].id, "4_voxel_size=0.1_variant=flow-only");
	EXPECT_TRUE(fs::exists(plan.runs[0].rawlog.path));
}

TEST(SweepSpec, ConstantsAreSetInEveryRunAndNamedInNoRunId)
{
	// [set] and a [grid] key of one value: the same in every run
	const auto d =
	    sweepFolder("constants",
	                "[sweep]\nconfigs = a.ini\nrawlogs = x.rawlog\n[grid]\n"
	                "grids.voxel_size = 0.05, 0.1\nflow.method = farneback\n"
	                "[set]\npipeline.variant = fused-raycast\n");
	const auto spec = sw::SweepSpec::load(d + "/sweep.ini");
	ASSERT_EQ(spec.grid.size(), 1u);
	const auto plan = sw::SweepPlan::make(spec);
	EXPECT_EQ(plan.gridKeys, std::vector<std::string>{"grids.voxel_size"});
	EXPECT_EQ(sw::constantsText(plan),
	          "flow.method=farneback, pipeline.variant=fused-raycast");
	ASSERT_EQ(plan.runs.size(), 2u);
	EXPECT_EQ(plan.runs[0].id, "1_voxel_size=0.05");
	EXPECT_EQ(plan.runs[1].id, "2_voxel_size=0.1");
	for (const auto& r : plan.runs)
	{
		mrpt::config::CConfigFileMemory mem(r.configText);
		EXPECT_EQ(mem.read_string("pipeline", "variant", ""), "fused-raycast");
		EXPECT_EQ(mem.read_string("flow", "method", ""), "farneback");
	}
	// kept in sweep.json for --collect
	const auto out = tmpDir("constants_out");
	sw::writePlan(plan, out);
	const auto back = sw::SweepPlan::readJson(out + "/sweep.json");
	EXPECT_EQ(back.constants, plan.constants);

	const std::string ok = "[sweep]\nconfigs = a.ini\nrawlogs = x.rawlog\n";
	EXPECT_NE(planError(sweepFolder("constants_bad",
	                                ok + "[set]\npipeline.variant = fsued\n"))
	              .find("[set] pipeline.variant = fsued: on a.ini: [pipeline] "
	                    "variant: 'fsued' is not one of"),
	          std::string::npos);
	EXPECT_NE(planError(sweepFolder("constants_twice",
	                                ok + "[grid]\npipeline.variant = fused, "
	                                     "flow-only\n[set]\npipeline.variant "
	                                     "= fused\n"))
	              .find("[set] pipeline.variant: also in [grid]"),
	          std::string::npos);
	EXPECT_NE(planError(sweepFolder("constants_key", ok + "[set]\nvariant = "
	                                                      "fused\n"))
	              .find("[set] variant: not an experiment key"),
	          std::string::npos);
}

TEST(SweepSpec, TruthNamesEachRawlogsLabelsAndTrajectory)
{
	const std::string two =
	    "[sweep]\nconfigs = a.ini\nrawlogs = x.rawlog "
	    "y.rawlog\n[truth]\n";
	// auto: the simulator's RAWLOG_gt/masks and RAWLOG_gt/groundtruth.txt
	auto d = sweepFolder("truth_auto", two +
	                                       "masks = auto\ntrajectory = "
	                                       "auto\nignore_values = 150\n");
	for (const std::string r : {"x", "y"})
	{
		fs::create_directories(d + "/" + r + "_gt/masks");
		put(d + "/" + r + "_gt/groundtruth.txt", "");
	}
	auto plan = sw::SweepPlan::make(sw::SweepSpec::load(d + "/sweep.ini"));
	ASSERT_EQ(plan.runs.size(), 2u);
	EXPECT_EQ(plan.runs[1].truthMasks, fs::path(d + "/y_gt/masks").string());
	EXPECT_EQ(plan.runs[1].truthTrajectory,
	          fs::path(d + "/y_gt/groundtruth.txt").string());
	EXPECT_EQ(plan.truth.ignoreValues, "150");
	EXPECT_TRUE(plan.truth.depthValid);
	const auto out = tmpDir("truth_out");
	sw::writePlan(plan, out);
	const auto back = sw::SweepPlan::readJson(out + "/sweep.json");
	EXPECT_EQ(back.runs[1].truthMasks, plan.runs[1].truthMasks);
	EXPECT_EQ(back.runs[0].truthTrajectory, plan.runs[0].truthTrajectory);
	EXPECT_EQ(back.truth.ignoreValues, "150");

	// one path per rawlog, relative to SWEEP.ini
	d = sweepFolder("truth_paths", two + "masks = lx ly\n");
	fs::create_directories(d + "/lx");
	fs::create_directories(d + "/ly");
	plan = sw::SweepPlan::make(sw::SweepSpec::load(d + "/sweep.ini"));
	EXPECT_EQ(plan.runs[0].truthMasks, fs::path(d + "/lx").string());
	EXPECT_EQ(plan.runs[0].truthTrajectory, "");

	EXPECT_NE(planError(sweepFolder("truth_gone", two + "masks = auto\n"))
	              .find("[truth] masks: auto: x.rawlog's no such folder"),
	          std::string::npos);
	EXPECT_NE(planError(sweepFolder("truth_count", two + "masks = lx\n"))
	              .find("[truth] masks: 'auto' or one path per rawlog (2), "
	                    "not 1"),
	          std::string::npos);
	EXPECT_NE(planError(sweepFolder("truth_empty", two + "depth_valid = no\n"))
	              .find("[truth] masks: required: masks, trajectory or both"),
	          std::string::npos);
}

TEST(SweepResults, ConstantsAreListedOnceAndLegendsUseFileStems)
{
	const auto d = tmpDir("constants_results");
	auto t = table(d);
	t.plan.constants = {{"flow.method", "farneback"}};
	for (auto& r : t.plan.runs) r.rawlog.written = "../data/x.rawlog";
	for (auto& row : t.rows) row.run.rawlog.written = "../data/x.rawlog";
	std::istringstream csv(sw::csvText(t));
	std::string head, row;
	std::getline(csv, head);
	std::getline(csv, row);
	EXPECT_EQ(head.rfind("id,config,rawlog,grids.voxel_size,pipeline.variant,"
	                     "flow.method,status,",
	                     0),
	          0u)
	    << head;
	EXPECT_EQ(row.rfind("1,a.ini,../data/x.rawlog,0.05,fused,farneback,ok,", 0),
	          0u)
	    << row;
	const std::string md = sw::markdownText(t, "fps");
	EXPECT_NE(md.find("Every run: flow.method=farneback."), std::string::npos)
	    << md;
	EXPECT_EQ(md.find("farneback"), md.rfind("farneback")) << md;

	const auto c = sw::resultsChart(t, "fps");
	EXPECT_EQ(c.series, std::vector<std::string>{"x"});
	EXPECT_NE(c.xLabel.find("every run: flow.method=farneback"),
	          std::string::npos)
	    << c.xLabel;
	for (const auto& g : c.groups)
		EXPECT_EQ(g.find("method"), std::string::npos) << g;
	EXPECT_EQ(c.groups.front(), "voxel_size=0.05\nvariant=fused");

	// two rawlogs of one stem keep their paths as written
	t.rows[1].run.rawlog.written = "../other/x.rawlog";
	EXPECT_EQ(
	    sw::resultsChart(t, "fps").series,
	    (std::vector<std::string>{"../data/x.rawlog", "../other/x.rawlog"}));
}

TEST(SweepResults, ScoresAndSharesHaveTheirAxisEndAtOne)
{
	EXPECT_EQ(sw::metricAxisTop("masks.total.f1"), 1.0);
	EXPECT_EQ(sw::metricAxisTop("masks.total.precision"), 1.0);
	EXPECT_EQ(sw::metricAxisTop("masks.total.recall"), 1.0);
	EXPECT_EQ(sw::metricAxisTop("static_called_moving_fraction"), 1.0);
	EXPECT_FALSE(sw::metricAxisTop("fps"));
	EXPECT_FALSE(sw::metricAxisTop("traj.ate.error_m.rmse"));
	EXPECT_FALSE(sw::metricAxisTop("f1_count"));
}
