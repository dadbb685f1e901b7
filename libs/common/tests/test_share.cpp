// share/bims found at run time: next to the program (the build tree's
// build/share/bims, an install prefix's PREFIX/share/bims), then in the
// install prefix compiled in.
#include <bims/common/share.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <bims_test/tmp_dir.h>
#include "bims_test/text.h"

namespace fs = std::filesystem;

namespace
{
}  // namespace

TEST(Share, ExecutableDirIsTheFolderOfThisTest)
{
	// test_common lives in build/bin with the programs
	ASSERT_FALSE(bims::executableDir().empty());
	EXPECT_TRUE(fs::equivalent(bims::executableDir(), BIMS_BIN_DIR));
}

TEST(Share, TheBuildTreeHoldsTheConfigsOfTheSourceTree)
{
	// build/bin/../share/bims: the build mirrors the installed layout
	for (const std::string name :
	     {"default.ini", "bonn.ini", "sim/crowded.ini", "README.md"})
	{
		const std::string p = bims::findShareFile(name);
		ASSERT_FALSE(p.empty()) << name;
		EXPECT_TRUE(fs::equivalent(
		    p, fs::path(BIMS_BIN_DIR) / ".." / "share" / "bims" / name))
		    << p;
		EXPECT_EQ(p, fs::path(p).lexically_normal().string());
	}
	EXPECT_EQ(bims::test::fileText(bims::findShareFile("default.ini")),
	          bims::test::fileText(std::string(BIMS_SOURCE_DIR) +
	                               "/config/default.ini"));
	EXPECT_EQ(bims::test::fileText(bims::findShareFile("sim/crowded.ini")),
	          bims::test::fileText(std::string(BIMS_SOURCE_DIR) +
	                               "/config/sim/crowded.ini"));
}

TEST(Share, AbsentFileOrAFolderIsEmpty)
{
	EXPECT_EQ(bims::findShareFile("no_such_file_in_share.ini"), "");
	EXPECT_EQ(bims::findShareFile("sim"), "");  // a folder, not a file
	EXPECT_EQ(bims::findShareFile(""), "");
}

TEST(Share, AnyPrefixIsFoundFromItsBinFolderAndMayBeMoved)
{
	// An install prefix anywhere (not the one compiled in): found from its
	// bin/ folder, and only from there.
	const fs::path prefix =
	    bims::test::tmpPath("bims_test_common", "share_prefix");
	fs::remove_all(prefix);
	fs::create_directories(prefix / "bin");
	fs::create_directories(prefix / "share" / "bims" / "sim");
	std::ofstream(prefix / "share" / "bims" / "sim" / "only_here.ini")
	    << "[x]\n";
	const std::string found =
	    bims::findShareFile("sim/only_here.ini", (prefix / "bin").string());
	EXPECT_EQ(found,
	          (prefix / "share" / "bims" / "sim" / "only_here.ini").string());
	// Moved: the program's new folder finds it there.
	const fs::path moved =
	    bims::test::tmpPath("bims_test_common", "share_prefix_moved");
	fs::remove_all(moved);
	fs::rename(prefix, moved);
	EXPECT_EQ(
	    bims::findShareFile("sim/only_here.ini", (moved / "bin").string()),
	    (moved / "share" / "bims" / "sim" / "only_here.ini").string());
	EXPECT_EQ(
	    bims::findShareFile("sim/only_here.ini", (prefix / "bin").string()),
	    "");
	fs::remove_all(moved);
}

TEST(Share, TheInstalledShareDirIsAnAbsolutePathEndingInBims)
{
	const fs::path d = bims::installedShareDir();
	EXPECT_TRUE(d.is_absolute()) << d;
	EXPECT_EQ(d.filename(), "bims") << d;
}

TEST(Share, ProgramsWithoutAnIniUseDefaultIniAndSayWhichFile)
{
	const std::string ini = bims::defaultExperimentIni();
	EXPECT_EQ(ini, bims::findShareFile("default.ini"));
	EXPECT_EQ(bims::parametersSource(ini), "parameters from " + ini);
	EXPECT_EQ(bims::parametersSource(""),
	          "parameters from built-in defaults (no share/bims/default.ini "
	          "found)");
}

// Issue 37: 'bims-run bonn.ini ...' and 'bims-sim sim/crowded.ini' gave "no
// such config file" outside the source tree, and the error did not say
// where presets are.
TEST(Share, APresetIsFoundByItsNameAndAMissingOneSaysWhereItLooked)
{
	const auto cwd = fs::current_path();
	const auto d = fs::temp_directory_path() / "bims_test_share_preset";
	fs::remove_all(d);
	fs::create_directories(d);
	fs::current_path(d);  // no bonn.ini here
	const std::string bonn = bims::resolvePreset("bonn.ini");
	const std::string crowded = bims::resolvePreset("sim/crowded.ini");
	const std::string none = bims::resolvePreset("none.ini");
	std::ofstream("bonn.ini") << "[sensors]\n";  // a file of that name wins
	const std::string local = bims::resolvePreset("bonn.ini");
	fs::current_path(cwd);
	EXPECT_EQ(bonn, bims::findShareFile("bonn.ini"));
	EXPECT_EQ(crowded, bims::findShareFile("sim/crowded.ini"));
	EXPECT_EQ(local, "bonn.ini");
	EXPECT_EQ(none, "none.ini");
	const std::string hint = bims::presetHint("none.ini");
	EXPECT_NE(hint.find("nor a preset of that name in "), std::string::npos);
	EXPECT_NE(
	    hint.find(
	        fs::path(bims::findShareFile("bonn.ini")).parent_path().string()),
	    std::string::npos)
	    << hint;
	EXPECT_EQ(bims::presetHint("/abs/none.ini"), "");
	EXPECT_EQ(bims::resolvePreset("/abs/bonn.ini"), "/abs/bonn.ini");
}
