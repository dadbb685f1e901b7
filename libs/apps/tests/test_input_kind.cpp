// Inputs of the wrong kind (bims/apps/input_kind.h): recognised by their
// content, each a usage error naming the command to use instead.
#include <bims/apps/app.h>
#include <bims/apps/input_kind.h>
#include <bims_test/error_of.h>
#include <bims_test/sample.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
using bims::apps::InputKind;
using bims::apps::inputKind;

namespace
{
/** The message of the UsageError that \a f throws ("" if none). */
std::string usageError(const std::function<void()>& f)
{
	return bims::test::errorOf<bims::UsageError>(f);
}
}  // namespace

TEST(InputKind, RecognisedByContent)
{
	const auto d = bims::test::freshTmpDir("bims_test_apps", "input_kind");
	fs::create_directories(d + "/tum");
	std::ofstream(d + "/tum/rgb.txt") << "# rgb\n";
	fs::create_directories(d + "/stray");
	std::ofstream(d + "/stray/odometry.csv") << "timestamp\n";
	fs::create_directories(d + "/empty");
	std::ofstream(d + "/scene.ini") << "# a scene\n[sim]\nframes = 3\n";
	std::ofstream(d + "/notes.txt") << "hello\n";
	std::ofstream(d + "/blank.rawlog");
	EXPECT_EQ(inputKind(d + "/tum"), InputKind::TumFolder);
	EXPECT_EQ(inputKind(d + "/stray"), InputKind::StrayFolder);
	EXPECT_EQ(inputKind(d + "/empty"), InputKind::Folder);
	EXPECT_EQ(inputKind(d + "/scene.ini"), InputKind::IniText);
	EXPECT_EQ(inputKind(d + "/notes.txt"), InputKind::OtherText);
	EXPECT_EQ(inputKind(d + "/blank.rawlog"), InputKind::Other);
	EXPECT_EQ(inputKind(d + "/bonn.rawlg"), InputKind::Missing);
	EXPECT_EQ(inputKind(bims::test::kSample), InputKind::Binary);
	EXPECT_EQ(inputKind(bims::test::kDefaultConfig), InputKind::IniText);
}

TEST(InputKind, BimsRunNamesTheCommandToUseInstead)
{
	const auto d = bims::test::freshTmpDir("bims_test_apps", "run_kinds");
	fs::create_directories(d + "/tum");
	std::ofstream(d + "/tum/depth.txt") << "# depth\n";
	const std::string cfg = bims::test::kDefaultConfig,
	                  in = bims::test::kSample;
	using bims::apps::checkRunInputKinds;
	// swapped
	auto e = usageError([&] { checkRunInputKinds(in, {cfg}); });
	EXPECT_NE(e.find("the arguments are swapped"), std::string::npos) << e;
	EXPECT_NE(e.find("bims-run " + cfg + " " + in + " -o OUTDIR"),
	          std::string::npos)
	    << e;
	// a rawlog where the .ini belongs
	e = usageError([&] { checkRunInputKinds(in, {in}); });
	EXPECT_NE(e.find("a binary file (a rawlog?) where the experiment .ini"),
	          std::string::npos)
	    << e;
	// an .ini where a rawlog belongs
	e = usageError([&] { checkRunInputKinds(cfg, {cfg}); });
	EXPECT_NE(e.find(cfg + ": an .ini where a rawlog belongs"),
	          std::string::npos)
	    << e;
	// an experiment .ini goes with a rawlog; a scene makes one
	EXPECT_NE(e.find("(an experiment .ini: it goes with a rawlog, e.g. "
	                 "bims-run " +
	                 cfg + " IN.rawlog -o OUTDIR)"),
	          std::string::npos)
	    << e;
	std::ofstream(d + "/scene.ini") << "; a scene\n  [sim]\nframes = 3\n";
	e = usageError([&] { checkRunInputKinds(cfg, {d + "/scene.ini"}); });
	EXPECT_NE(e.find("(a simulator scene makes a rawlog: bims-sim " + d +
	                 "/scene.ini -o OUT.rawlog)"),
	          std::string::npos)
	    << e;
	// a TUM folder, as the rawlog or as the .ini
	e = usageError([&] { checkRunInputKinds(cfg, {d + "/tum"}); });
	EXPECT_NE(e.find("bims-import-tum " + d + "/tum -o OUT.rawlog"),
	          std::string::npos)
	    << e;
	e = usageError([&] { checkRunInputKinds(d + "/tum", {in}); });
	EXPECT_NE(e.find("bims-import-tum " + d + "/tum -o OUT.rawlog"),
	          std::string::npos)
	    << e;
	// a plain folder
	e = usageError([&] { checkRunInputKinds(cfg, {d}); });
	EXPECT_NE(e.find(d + ": a folder, not a rawlog file"), std::string::npos)
	    << e;
	// right, a preset by name, a typo (left to the reader, which names it)
	EXPECT_EQ(usageError([&] { checkRunInputKinds(cfg, {in, in}); }), "");
	EXPECT_EQ(usageError([&] { checkRunInputKinds("bonn.ini", {in}); }), "");
	EXPECT_EQ(usageError([&] { checkRunInputKinds(cfg, {d + "/x.rawlg"}); }),
	          "");
}
