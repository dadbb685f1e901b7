// One command-line vocabulary for every program (docs/cli.md): the shared
// options spelled the same way in every --help, every option of every
// program in the one table of docs/cli.md and in its man page, old
// spellings still taken with a note, and the progress line of long
// commands when stderr is not a terminal.
#include <bims_test/run_command.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
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
const std::string kManDir = BIMS_MAN_DIR;  // "" without help2man
const std::string kSample = kSrc + "/rawlogs/pendulum_slow.rawlog";
const std::string kConfig = kSrc + "/config/default.ini";

/** Every program, bims-eval by sub-command. */
const std::vector<std::string> kPrograms = {
    "bims-run",         "bims-viewer",      "bims-grab",
    "bims-sim",         "bims-odom",        "bims-calib-imu",
    "bims-calib-depth", "bims-import-tum",  "bims-import-stray",
    "bims-eval traj",   "bims-eval masks",  "bims-eval depth-consistency",
    "bims-info",        "bims-flow-labels", "bims-flow-check",
    "bims-sweep",       "bims-maps-figure", "bims-import-bag",
    "bims-ros2"};

bool built(const std::string& program)
{
	return fs::exists(kBin + "/" + program.substr(0, program.find(' ')));
}

/** An option as --help prints it: "-o <OUTDIR>,  --out <OUTDIR>". */
struct Option
{
	std::string shortName, longName, value;  // "-o", "--out", "OUTDIR"
};

/** The options of a program's --help (TCLAP's "Where:" list), by long
 * name (or short name when it has none). */
std::map<std::string, Option> optionsOf(const std::string& program)
{
	const auto r = bims::test::runCommand(kBin + "/" + program + " --help");
	EXPECT_EQ(r.code, 0) << program << "\n" << r.out;
	std::map<std::string, Option> opts;
	std::istringstream in(r.out);
	const std::regex line(
	    R"(^   (-[^ ,<]+)(?: <([^>]*)>)?(?:,  (--[^ <]+)(?: <[^>]*>)?)?\s*$)");
	for (std::string l; std::getline(in, l);)
	{
		std::smatch m;
		if (!std::regex_match(l, m, line)) continue;
		Option o;
		o.value = m[2];
		if (m[3].matched)
			o.shortName = m[1], o.longName = m[3];
		else if (std::string(m[1]).rfind("--", 0) == 0)
			o.longName = m[1];
		else
			o.shortName = m[1];
		if (o.longName == "--ignore_rest") continue;  // TCLAP's "--"
		opts[o.longName.empty() ? o.shortName : o.longName] = o;
	}
	EXPECT_FALSE(opts.empty()) << program << "\n" << r.out;
	return opts;
}

/** docs/cli.md's table: option (long name, or short) -> the programs of
 * its row ("every program" stands for all). */
std::map<std::string, std::set<std::string>> docsTable()
{
	std::map<std::string, std::set<std::string>> rows;
	std::istringstream in(bims::test::fileText(kSrc + "/docs/cli.md"));
	const std::regex name("`(--?[a-z][a-z0-9-]*)");
	bool inTable = false;  // the table under "## Every option"
	for (std::string l; std::getline(in, l);)
	{
		if (l.rfind("## ", 0) == 0) inTable = l == "## Every option";
		if (!inTable || l.rfind("| `-", 0) != 0) continue;
		const auto cells = l.substr(1, l.size() - 2);
		const auto first = cells.substr(0, cells.find('|'));
		std::string last = cells.substr(cells.rfind('|') + 1);
		last = last.substr(0, last.find_last_not_of(' ') + 1) + ",";
		std::set<std::string> programs;
		for (const auto& p : kPrograms)
			if (last.find("every program") != std::string::npos ||
			    last.find(" " + p + ",") != std::string::npos)
				programs.insert(p);
		for (std::sregex_iterator it(first.begin(), first.end(), name), end;
		     it != end; ++it)
			rows[(*it)[1]].insert(programs.begin(), programs.end());
	}
	return rows;
}
}  // namespace

TEST(Cli, SharedOptionsAreSpelledTheSameWayInEveryProgram)
{
	// the vocabulary: the short name and the value of each shared option
	struct Shared
	{
		std::string shortName, value;  // "" value: a switch; "*": any
	};
	const std::map<std::string, Shared> shared = {
	    {"--out", {"-o", "*"}},      {"--quiet", {"-q", ""}},
	    {"--config", {"-c", "*"}},   {"--frames", {"", "A:B"}},
	    {"--max-frames", {"", "N"}}, {"--overwrite", {"", ""}},
	    {"--version", {"", ""}},     {"--help", {"-h", ""}},
	    {"--seed", {"-s", "N"}}};
	// spellings the vocabulary replaced
	const std::set<std::string> retired = {
	    "--output",     "--plot",  "--plot-dir", "--experiment", "--outdir",
	    "--max_frames", "--frame", "--nframes",  "--silent"};
	// who must have them: outputs (-o), a progress line or chatter (-q)
	const std::set<std::string> withOut = {
	    "bims-run",          "bims-sim",        "bims-grab",
	    "bims-odom",         "bims-calib-imu",  "bims-calib-depth",
	    "bims-import-tum",   "bims-eval traj",  "bims-eval masks",
	    "bims-flow-labels",  "bims-sweep",      "bims-maps-figure",
	    "bims-import-stray", "bims-import-bag", "bims-ros2"};
	const std::set<std::string> withQuiet = {
	    "bims-run",        "bims-sim",          "bims-grab",
	    "bims-odom",       "bims-calib-imu",    "bims-calib-depth",
	    "bims-import-tum", "bims-eval masks",   "bims-flow-check",
	    "bims-sweep",      "bims-import-stray", "bims-import-bag"};
	size_t checked = 0;
	for (const auto& p : kPrograms)
	{
		if (!built(p)) continue;  // bims-grab without OpenNI2, no GUI
		const auto opts = optionsOf(p);
		for (const auto& [key, o] : opts)
		{
			EXPECT_EQ(retired.count(o.longName), 0u)
			    << p << ": " << o.longName << " is retired (docs/cli.md)";
			const auto s = shared.find(o.longName);
			if (s != shared.end())
			{
				EXPECT_EQ(o.shortName, s->second.shortName)
				    << p << " " << o.longName;
				if (s->second.value != "*")
				{
					EXPECT_EQ(o.value, s->second.value)
					    << p << " " << o.longName;
				}
			}
			// a shared short name means the shared option
			for (const auto& [name, sh] : shared)
			{
				if (!o.shortName.empty() && o.shortName == sh.shortName)
				{
					EXPECT_EQ(o.longName, name) << p << " " << o.shortName;
				}
			}
			++checked;
		}
		EXPECT_EQ(opts.count("--version"), 1u) << p;
		EXPECT_EQ(opts.count("--help"), 1u) << p;
		EXPECT_EQ(opts.count("--out"), withOut.count(p)) << p << " -o";
		EXPECT_EQ(opts.count("--quiet"), withQuiet.count(p)) << p << " -q";
	}
	EXPECT_GT(checked, 100u);
}

TEST(Cli, EveryOptionOfEveryProgramIsInTheOneTableOfDocsCli)
{
	const auto table = docsTable();
	ASSERT_GT(table.size(), 30u);
	for (const auto& p : kPrograms)
	{
		if (!built(p)) continue;
		for (const auto& [key, o] : optionsOf(p))
		{
			const auto row = table.find(key);
			ASSERT_NE(row, table.end())
			    << key << " (" << p << ") has no row in docs/cli.md";
			EXPECT_EQ(row->second.count(p), 1u)
			    << "docs/cli.md: the row of " << key << " does not name " << p;
		}
	}
	// and every program there is a program: a new one needs its rows
	for (const auto& e : fs::directory_iterator(kBin))
	{
		const std::string n = e.path().filename().string();
		if (n.rfind("bims-", 0) != 0 || n.find('.') != std::string::npos)
			continue;
		bool listed = false;
		for (const auto& p : kPrograms) listed |= p.substr(0, p.find(' ')) == n;
		EXPECT_TRUE(listed) << n << " is not in this test's list of programs";
	}
	// README links the table
	EXPECT_NE(bims::test::fileText(kSrc + "/README.md").find("docs/cli.md"),
	          std::string::npos);
}

TEST(Cli, EachProgramHasAManPageNamingItsOptions)
{
	if (kManDir.empty()) GTEST_SKIP() << "built without help2man";
	for (const auto& p : kPrograms)
	{
		if (!built(p)) continue;
		const std::string program = p.substr(0, p.find(' '));
		const std::string page = kManDir + "/" + program + ".1";
		ASSERT_TRUE(fs::exists(page)) << page;
		const std::string text = bims::test::fileText(page);
		EXPECT_NE(text.find(".SH NAME\n" + program + " \\- "),
		          std::string::npos)
		    << page;
		// the program by its name, not by the build's path
		EXPECT_EQ(text.find("/bin/"), std::string::npos) << page;
		for (const auto& [key, o] : optionsOf(p))
		{
			// groff writes '-' as '\-'
			const std::string roff =
			    std::regex_replace(key, std::regex("-"), "\\-");
			EXPECT_NE(text.find(roff), std::string::npos)
			    << page << " does not name " << key;
		}
	}
}

TEST(Cli, OldSpellingsStillWorkWithOneNote)
{
	const std::string d = bims::test::freshTmpDir("bims_test_cli", "old");
	// bims-sim --frames N (a count) is now --max-frames N
	const auto sim = bims::test::runCommand(
	    kBin + "/bims-sim " + kSrc + "/config/sim/pendulum_slow.ini -o " + d +
	    "/s.rawlog -r 320x240 --frames 2 -q");
	EXPECT_EQ(sim.code, 0) << sim.out;
	EXPECT_NE(
	    sim.out.find("bims-sim: note: --frames 2 is now --max-frames 2\n"),
	    std::string::npos)
	    << sim.out;
	EXPECT_NE(sim.out.find("bims-sim: 2 frames"), std::string::npos) << sim.out;
	// bims-eval traj --plot FILE is now --out FILE
	const std::string gt = kSrc + "/rawlogs/pendulum_slow_gt/groundtruth.txt";
	const auto traj =
	    bims::test::runCommand(kBin + "/bims-eval traj " + gt + " " + gt +
	                           " --plot " + d + "/t.png --delta 0.01");
	EXPECT_NE(traj.out.find("bims-eval traj: note: --plot " + d +
	                        "/t.png is now --out " + d + "/t.png"),
	          std::string::npos)
	    << traj.out;
	EXPECT_TRUE(fs::exists(d + "/t.png")) << traj.out;
}

namespace
{
/** The lines of \a text that contain \a what. */
std::vector<std::string> linesWith(const std::string& text,
                                   const std::string& what)
{
	std::vector<std::string> v;
	std::istringstream in(text);
	for (std::string l; std::getline(in, l);)
		if (l.find(what) != std::string::npos) v.push_back(l);
	return v;
}
}  // namespace

TEST(Cli, RedirectedLongCommandsPrintPlainProgressLinesWithTotalRateAndEta)
{
	const std::string d = bims::test::freshTmpDir("bims_test_cli", "progress");
	// stderr to a file: not a terminal
	const auto sim = bims::test::runCommand(
	    "(" + kBin + "/bims-sim " + kSrc + "/config/sim/pendulum_slow.ini -o " +
	    d + "/s.rawlog -r 320x240 --max-frames 20 2> " + d + "/sim.err)");
	ASSERT_EQ(sim.code, 0) << sim.out;
	const std::string err = bims::test::fileText(d + "/sim.err");
	EXPECT_EQ(err.find('\r'), std::string::npos);
	const std::regex simLine(
	    R"(^bims-sim: \d+/20 frames \(\d+ %\), [0-9.]+ frames/s, [0-9.]+ s, ETA [0-9.]+ s$)");
	size_t n = 0;
	for (const auto& l : linesWith(err, "bims-sim: "))
		n += std::regex_match(l, simLine);
	EXPECT_GE(n, 3u) << err;
	EXPECT_EQ(linesWith(err, "bims-sim: 20/20 frames (100 %)").size(), 1u)
	    << err;

	// bims-run over the whole input: the total estimated from the share of
	// the input read ("~150")
	const auto run = bims::test::runCommand("(" + kBin + "/bims-run " +
	                                        kConfig + " " + kSample + " -o " +
	                                        d + "/out 2> " + d + "/run.err)");
	ASSERT_EQ(run.code, 0) << run.out << bims::test::fileText(d + "/run.err");
	const std::string rerr = bims::test::fileText(d + "/run.err");
	EXPECT_EQ(rerr.find('\r'), std::string::npos);
	const std::regex runLine(
	    R"(^bims-run: \d+/~\d+ frames \(\d+ %\), [0-9.]+ frames/s, [0-9.]+ s, ETA [0-9.]+ s, frame \d+$)");
	n = 0;
	for (const auto& l : linesWith(rerr, "bims-run: "))
		n += std::regex_match(l, runLine);
	EXPECT_GE(n, 3u) << rerr;
	EXPECT_EQ(linesWith(rerr, "bims-run: 150/150 frames (100 %)").size(), 1u)
	    << rerr;
	// bims-odom (and bims-calib-depth, the same replay): estimated too
	const auto odom = bims::test::runCommand(
	    "(" + kBin + "/bims-odom " + kConfig + " " + kSample + " -o " + d +
	    "/odom.txt 2> " + d + "/odom.err)");
	ASSERT_EQ(odom.code, 0) << odom.out;
	const std::regex odomLine(
	    R"(^bims-odom: \d+/~\d+ frames \(\d+ %\), [0-9.]+ frames/s, [0-9.]+ s, ETA [0-9.]+ s$)");
	n = 0;
	for (const auto& l :
	     linesWith(bims::test::fileText(d + "/odom.err"), "bims-odom: "))
		n += std::regex_match(l, odomLine);
	EXPECT_GE(n, 3u) << bims::test::fileText(d + "/odom.err");
	// -q: none
	const auto quiet = bims::test::runCommand(
	    "(" + kBin + "/bims-run " + kConfig + " " + kSample + " -o " + d +
	    "/out2 --frames 0:4 -q 2> " + d + "/q.err)");
	ASSERT_EQ(quiet.code, 0) << quiet.out;
	EXPECT_TRUE(
	    linesWith(bims::test::fileText(d + "/q.err"), " frames (").empty());
}

TEST(Cli, AFrameRangeBeyondTheInputIsAUsageErrorBeforeAnyWork)
{
	const std::string d = bims::test::freshTmpDir("bims_test_cli", "range");
	const std::string gt = kSrc + "/rawlogs/pendulum_slow_gt/groundtruth.txt";
	for (const std::string& args :
	     {"bims-run " + kConfig + " " + kSample + " -o " + d + "/out",
	      "bims-flow-check " + kConfig + " " + kSample + " --gt " + gt +
	          " --csv " + d + "/out.csv",
	      "bims-calib-depth " + kConfig + " " + kSample + " -o " + d +
	          "/out.ini"})
	{
		const auto r =
		    bims::test::runCommand(kBin + "/" + args + " --frames 500:600");
		EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
		EXPECT_NE(
		    r.out.find("usage error: --frames 500:600: the input (" + kSample +
		               ") has 150 3D scans (0 to 149) with label "
		               "'RGBD'"),
		    std::string::npos)
		    << args << "\n"
		    << r.out;
		const auto part =
		    bims::test::runCommand(kBin + "/" + args + " --frames 140:160");
		EXPECT_EQ(part.code, 2) << args << "\n" << part.out;
		EXPECT_NE(part.out.find("--frames 140:160: the input"),
		          std::string::npos)
		    << part.out;
		EXPECT_NE(part.out.find("; --frames 140: runs to its end"),
		          std::string::npos)
		    << part.out;
	}
	EXPECT_TRUE(fs::is_empty(d));  // nothing written
}

// Issue 39: --max-frames -1 meant "all" in four programs, and
// --max-correction -1, --depth-scale 0, --fx -542 were taken. Each numeric
// option is range-checked where the program reads it, before any work.
TEST(Cli, NumericOptionsOutOfTheirRangeAreUsageErrors)
{
	const std::string d = bims::test::freshTmpDir("bims_test_cli", "numeric");
	const std::string png = kSrc + "/rawlogs/pendulum_slow_gt/masks/000000.png";
	for (const auto& [args, want] :
	     std::vector<std::pair<std::string, std::string>>{
	         {"bims-import-tum " + d + " -o " + d + "/x.rawlog --max-frames -1",
	          "--max-frames -1: out of range [0, 100000000]"},
	         {"bims-import-stray " + d + " -o " + d +
	              "/x.rawlog --max-frames -1",
	          "--max-frames -1: out of range"},
	         {"bims-import-bag " + d + "/x.bag -o " + d +
	              "/x.rawlog --max-frames -1",
	          "--max-frames -1: out of range"},
	         {"bims-odom " + kConfig + " " + kSample + " -o " + d +
	              "/t.txt --max-frames -1",
	          "--max-frames -1: out of range"},
	         {"bims-eval depth-consistency " + kSample + " " + kSrc +
	              "/rawlogs/pendulum_slow_gt/groundtruth.txt --max-frames -2",
	          "--max-frames -2: out of range"},
	         {"bims-calib-depth " + kConfig + " " + kSample + " -o " + d +
	              "/c.ini --max-correction -1",
	          "--max-correction -1: out of range"},
	         {"bims-flow-labels " + png + " " + png + " " + png + " -o " + d +
	              "/f --depth-scale 0",
	          "--depth-scale 0: out of range"},
	         {"bims-flow-labels " + png + " " + png + " " + png + " -o " + d +
	              "/f --fx -542",
	          "--fx -542: out of range"},
	         {"bims-flow-labels " + png + " " + png + " " + png + " -o " + d +
	              "/f --fx 0",
	          "--fx 0: out of range"}})
	{
		const auto r = bims::test::runCommand(kBin + "/" + args);
		EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
		EXPECT_NE(r.out.find(want), std::string::npos) << args << "\n" << r.out;
	}
	EXPECT_TRUE(fs::is_empty(d));  // nothing written
}

TEST(Cli, MapsFigureTakesItsOutputAsOOrAsTheThirdWordOnce)
{
	if (!built("bims-maps-figure")) GTEST_SKIP() << "not built";
	const std::string d = bims::test::freshTmpDir("bims_test_cli", "figure");
	const std::string args = kBin + "/bims-maps-figure " + kSample + " " +
	                         kSrc + "/rawlogs/pendulum_slow_gt";
	for (const std::string& out :
	     {std::string(), " " + d + "/a.png -o " + d + "/b.png"})
	{
		const auto r = bims::test::runCommand(args + out);
		EXPECT_EQ(r.code, 2) << out << "\n" << r.out;
		EXPECT_NE(r.out.find("give the output PNG once: -o OUT.png or as the "
		                     "third word"),
		          std::string::npos)
		    << r.out;
	}
	EXPECT_FALSE(fs::exists(d + "/a.png") || fs::exists(d + "/b.png"));
}

// Issue 39: bims-maps-figure paired the poses with the scans by line, so
// another recording's ground truth gave a picture. Pairs are by time stamp:
// a ground truth without a pose at any scan's time is an error naming it,
// and a pose missing at the start shifts nothing.
TEST(Cli, MapsFigurePairsPosesByTimeAndRefusesAnotherRecordingsGroundTruth)
{
	if (!built("bims-maps-figure")) GTEST_SKIP() << "not built";
	const std::string d =
	    bims::test::freshTmpDir("bims_test_cli", "figure_time");
	const std::string gtText = bims::test::fileText(
	    kSrc + "/rawlogs/pendulum_slow_gt/groundtruth.txt");
	// another recording: the same poses 1000 s later
	fs::create_directories(d + "/other");
	{
		std::istringstream in(gtText);
		std::ofstream out(d + "/other/groundtruth.txt");
		for (std::string line; std::getline(in, line);)
		{
			if (line.empty() || line[0] == '#')
			{
				out << line << "\n";
				continue;
			}
			const size_t sp = line.find(' ');
			char t[64];
			std::snprintf(t, sizeof(t), "%.6f",
			              std::stod(line.substr(0, sp)) + 1000);
			out << t << line.substr(sp) << "\n";
		}
	}
	const auto r =
	    bims::test::runCommand(kBin + "/bims-maps-figure " + kSample + " " + d +
	                           "/other -o " + d + "/other.png --max-frames 10");
	EXPECT_EQ(r.code, 1) << r.out;
	EXPECT_NE(r.out.find(d + "/other/groundtruth.txt: no pose within 0.02"),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("of any of the first 10 3D scans of " + kSample),
	          std::string::npos)
	    << r.out;
	EXPECT_NE(r.out.find("the ground truth of another recording?"),
	          std::string::npos)
	    << r.out;
	EXPECT_FALSE(fs::exists(d + "/other.png"));
	// the first 4 poses missing: scans 0-3 skipped, 4-9 at their own poses
	fs::create_directories(d + "/late");
	{
		std::istringstream in(gtText);
		std::ofstream out(d + "/late/groundtruth.txt");
		int poses = 0;
		for (std::string line; std::getline(in, line);)
			if (line.empty() || line[0] == '#' || poses++ >= 4)
				out << line << "\n";
	}
	const auto late =
	    bims::test::runCommand(kBin + "/bims-maps-figure " + kSample + " " + d +
	                           "/late -o " + d + "/late.png --max-frames 10");
	EXPECT_NE(late.out.find("4 of the first 10 3D scans have no "
	                        "ground-truth pose within 0.02 s: skipped"),
	          std::string::npos)
	    << late.out;
	if (late.code == 0)  // drawn where OpenGL renders off screen
	{
		EXPECT_NE(late.out.find("\n6 frames; "), std::string::npos) << late.out;
	}
}

// Issue 37: a program without its arguments said only TCLAP's "One or
// more required arguments missing!", never which.
TEST(Cli, MissingArgumentsAreNamed)
{
	for (const auto& [args, want] :
	     std::vector<std::pair<std::string, std::vector<std::string>>>{
	         {"bims-run", {"bims-run: usage error: missing", "-o"}},
	         {"bims-odom " + kConfig, {"missing", "<IN.rawlog>", "-o"}},
	         {"bims-import-bag", {"missing <BAG>"}},
	         {"bims-import-bag x.bag", {"-o OUT.rawlog is required"}},
	         {"bims-sim", {"bims-sim: usage error: missing", "-o"}},
	         {"bims-import-stray", {"missing", "<FOLDER>", "-o"}}})
	{
		if (!built(args.substr(0, args.find(' ')))) continue;
		const auto r = bims::test::runCommand(kBin + "/" + args);
		EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
		for (const auto& w : want)
			EXPECT_NE(r.out.find(w), std::string::npos)
			    << args << ": " << w << "\n"
			    << r.out;
	}
}
