#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims_test/error_of.h>
#include <gtest/gtest.h>

#include <bims_test/tmp_dir.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <set>

using bims::ConfigError;
using bims::ConfigSection;

using bims::test::errorOf;

namespace
{
}  // namespace

TEST(ConfigSection, ReadsTypedValuesAndDefaults)
{
	mrpt::config::CConfigFileMemory cfg(
	    "[a]\nx = 1.5\nn = 7\nflag = yes\nname = hello\nmode = fast\nv = 1, 2 "
	    ",3\n");
	ConfigSection s(cfg, "a");
	EXPECT_DOUBLE_EQ(s.getDouble("x", 0, 0, 10), 1.5);
	EXPECT_EQ(s.getInt("n", 0, 0, 10), 7);
	EXPECT_TRUE(s.getBool("flag", false));
	EXPECT_EQ(s.getString("name", ""), "hello");
	EXPECT_EQ(s.getChoice("mode", "slow", {"slow", "fast"}), "fast");
	EXPECT_EQ(s.getDoubles("v", {}, 3, -10, 10),
	          (std::vector<double>{1, 2, 3}));
	EXPECT_DOUBLE_EQ(s.getDouble("absent", 4.25, 0, 10), 4.25);
	EXPECT_NO_THROW(s.finish());
}

TEST(ConfigSection, ListsOfWordsAndOfCommaSeparatedItems)
{
	mrpt::config::CConfigFileMemory cfg(
	    "[a]\nfiles =  x.ini\ty.ini  z.ini\nvalues = fused , flow-only,0.5\n"
	    "gap = a,,b\nend = a, b,\nblank =\n");
	ConfigSection s(cfg, "a");
	EXPECT_EQ(s.getWords("files"),
	          (std::vector<std::string>{"x.ini", "y.ini", "z.ini"}));
	EXPECT_EQ(s.getList("values"),
	          (std::vector<std::string>{"fused", "flow-only", "0.5"}));
	EXPECT_TRUE(s.getWords("absent").empty());
	EXPECT_TRUE(s.getList("absent2").empty());
	for (const char* k : {"gap", "end", "blank"})
		EXPECT_NE(errorOf<bims::ConfigError>([&] { s.getList(k); })
		              .find(std::string("[a] ") + k + ": '"),
		          std::string::npos)
		    << k;
	EXPECT_NO_THROW(s.finish());
}

TEST(ConfigSection, UnknownKeyIsAnErrorNamingSectionAndKey)
{
	mrpt::config::CConfigFileMemory cfg("[a]\nx = 1\nxx = 2\n");
	ConfigSection s(cfg, "a");
	s.getDouble("x", 0, 0, 10);
	const auto msg = errorOf<bims::ConfigError>([&] { s.finish(); });
	EXPECT_NE(msg.find("[a] xx: unknown key"), std::string::npos) << msg;
	EXPECT_NE(msg.find("<memory>"), std::string::npos) << msg;
}

TEST(ConfigSection, OutOfRangeAndMalformedValuesAreErrors)
{
	mrpt::config::CConfigFileMemory cfg(
	    "[a]\nx = 11\ny = abc\nn = 2.5\nb = maybe\nm = other\nv = 1 2\n");
	ConfigSection s(cfg, "a");
	EXPECT_NE(errorOf<bims::ConfigError>([&] { s.getDouble("x", 0, 0, 10); })
	              .find("out of range"),
	          std::string::npos);
	EXPECT_NE(errorOf<bims::ConfigError>([&] { s.getDouble("y", 0, 0, 10); })
	              .find("[a] y:"),
	          std::string::npos);
	EXPECT_NE(errorOf<bims::ConfigError>([&] { s.getInt("n", 0, 0, 10); })
	              .find("not an integer"),
	          std::string::npos);
	EXPECT_NE(errorOf<bims::ConfigError>([&] { s.getBool("b", false); })
	              .find("not a boolean"),
	          std::string::npos);
	EXPECT_NE(errorOf<bims::ConfigError>(
	              [&] {
		              s.getChoice("m", "a", {"a", "b"});
	              })
	              .find("a|b"),
	          std::string::npos);
	EXPECT_NE(
	    errorOf<bims::ConfigError>([&] { s.getDoubles("v", {}, 3, 0, 9); })
	        .find("expected 3"),
	    std::string::npos);
}

TEST(ConfigSection, RequiredKeysAndSections)
{
	mrpt::config::CConfigFileMemory cfg("[a]\nx = 1\n");
	EXPECT_NE(errorOf<bims::ConfigError>([&] { ConfigSection(cfg, "b", true); })
	              .find("missing required section [b]"),
	          std::string::npos);
	ConfigSection s(cfg, "a");
	EXPECT_NE(errorOf<bims::ConfigError>([&] { s.requireDouble("y", 0, 1); })
	              .find("required key"),
	          std::string::npos);
	EXPECT_DOUBLE_EQ(s.requireDouble("x", 0, 1), 1.0);
}

TEST(ConfigSection, UnknownSectionsAreErrors)
{
	mrpt::config::CConfigFileMemory cfg(
	    "[a]\nx=1\n[map_voxel_00]\ny=2\n[oops]\nz=3\n");
	const auto msg = errorOf<bims::ConfigError>(
	    [&] { bims::checkSections(cfg, {"a"}, {"map_"}); });
	EXPECT_NE(msg.find("[oops]: unknown section"), std::string::npos) << msg;
}

// The tests' scratch folders (bims_test/tmp_dir.h) are in their build
// tree (TMPDIR set by CTest: cmake/BimsHelpers.cmake): two trees tested at
// once never share one.
TEST(TestSupport, ScratchFoldersAreInTheBuildTree)
{
	const std::string tmp = bims::test::tmpPath("bims_test_common", "x");
	EXPECT_EQ(tmp.rfind(std::string(BIMS_BINARY_DIR) + "/test-tmp/", 0), 0u)
	    << tmp;
}

// The one table of the experiment's sections: unique names, each with who
// reads it and a title; a name not in it is a program's error.
TEST(ExperimentSections, OneTableNamesReadersAndTitles)
{
	const auto& t = bims::experimentSectionTable();
	ASSERT_EQ(bims::experimentSections().size(), t.size());
	std::set<std::string> names;
	for (size_t k = 0; k < t.size(); ++k)
	{
		EXPECT_TRUE(names.insert(t[k].name).second) << t[k].name;
		EXPECT_EQ(bims::experimentSections()[k], t[k].name);
		EXPECT_GT(std::string(t[k].readBy).size(), 2u) << t[k].name;
		EXPECT_GT(std::string(t[k].title).size(), 5u) << t[k].name;
		EXPECT_EQ(&bims::experimentSection(t[k].name), &t[k]);
	}
	EXPECT_THROW(bims::experimentSection("nope"), std::logic_error);
	mrpt::config::CConfigFileMemory cfg(
	    "[grids]\nx = 1\n[import_bag]\ny = 1\n[gridz]\nz = 1\n");
	EXPECT_NE(
	    errorOf<bims::ConfigError>([&] { bims::checkExperimentSections(cfg); })
	        .find("[gridz]: unknown section"),
	    std::string::npos);
}

namespace
{
/** The ConfigError of checking an .ini file holding \a text ("" if none). */
std::string iniError(const std::string& text, const std::string& name)
{
	const auto p = bims::test::tmpPath("bims_test_common", name);
	std::ofstream(p) << text;
	return errorOf<bims::ConfigError>([&] { bims::checkIniFile(p); });
}
}  // namespace

TEST(IniSyntax, AWellFormedFileWithCommentsPasses)
{
	EXPECT_EQ(iniError("; comment\n# comment\n// comment\n@define X 1\n\n"
	                   "[a]\nx = 1\ny=\n[b : a]\nx = 2\n",
	                   "ok.ini"),
	          "");
}

TEST(IniSyntax, EveryMalformedCaseNamesFileAndLine)
{
	const std::vector<std::pair<std::string, std::string>> cases = {
	    {"[a]\nx = 1\nx = 2\n",
	     "dup_key.ini:3: [a] x given twice (first on line 2)"},
	    {"[a]\nX = 1\nx = 2\n",
	     "dup_case.ini:3: [a] x given twice (first on line 2)"},
	    {"[a]\nx = 1\n[b]\n[a]\n",
	     "dup_sec.ini:4: section [a] given twice (first on line 1)"},
	    {"x = 1\n[a]\n", "no_sec.ini:1: key 'x' before the first [section]"},
	    {"[a]\nx 1\n",
	     "no_eq.ini:2: 'x 1' is neither [section] nor key = value"},
	    {"[a\nx = 1\n",
	     "open_sec.ini:1: section header '[a' has no closing ']'"},
	    {"[a]\n = 1\n", "no_key.ini:2: a value without a key"}};
	for (const auto& [text, want] : cases)
	{
		const auto name = want.substr(0, want.find(':'));
		const auto msg = iniError(text, name);
		EXPECT_NE(msg.find(want), std::string::npos) << msg;
	}
	// the same key in two sections is no duplicate
	EXPECT_EQ(iniError("[a]\nx = 1\n[b]\nx = 1\n", "two_sections.ini"), "");
}

TEST(IniSyntax, AFolderOrAMissingFileIsNamed)
{
	const auto dir =
	    std::filesystem::temp_directory_path() / "bims_test_common";
	std::filesystem::create_directories(dir / "a_folder.ini");
	EXPECT_NE(errorOf<bims::ConfigError>(
	              [&] { bims::checkIniFile((dir / "a_folder.ini").string()); })
	              .find("a_folder.ini: not a regular file"),
	          std::string::npos);
	EXPECT_NE(errorOf<bims::ConfigError>(
	              [&] { bims::checkIniFile((dir / "missing.ini").string()); })
	              .find("missing.ini: no such config file"),
	          std::string::npos);
}

TEST(IniSyntax, EveryBundledIniPasses)
{
	size_t n = 0;
	for (const auto* sub : {"config", "config/sim", "rawlogs", "share"})
	{
		const auto d = std::filesystem::path(BIMS_SOURCE_DIR) / sub;
		if (!std::filesystem::is_directory(d)) continue;
		for (const auto& e : std::filesystem::recursive_directory_iterator(d))
			if (e.path().extension() == ".ini")
			{
				EXPECT_EQ(errorOf<bims::ConfigError>(
				              [&] { bims::checkIniFile(e.path().string()); }),
				          "")
				    << e.path();
				n++;
			}
	}
	EXPECT_GT(n, 5u);
}

// What MRPT's reader would take wrong or silently skip is refused, naming
// the file and line; MRPT's own errors come out on one line.
TEST(IniSyntax, BomIncludeAndBinaryBytesAreRefused)
{
	const auto bom = iniError("\xEF\xBB\xBF[a]\nx = 1\n", "bom.ini");
	EXPECT_NE(bom.find("bom.ini:1: the file starts with a UTF-8 byte-order "
	                   "mark"),
	          std::string::npos)
	    << bom;
	const auto inc = iniError("@include other.ini\n[a]\nx = 1\n", "inc.ini");
	EXPECT_NE(inc.find("inc.ini:1: '@include': MRPT's reader takes only "
	                   "@define"),
	          std::string::npos)
	    << inc;
	EXPECT_NE(iniError("[a]\n@defineX 1\n", "d.ini").find("d.ini:2:"),
	          std::string::npos);
	const auto bin =
	    iniError(std::string("[a]\nx = 1\n\x01\x02\x03\n", 13), "bin.ini");
	EXPECT_NE(bin.find("bin.ini:3: binary bytes: not a text .ini file"),
	          std::string::npos)
	    << bin;
}

TEST(IniSyntax, OpenIniFileTurnsMrptErrorsIntoOneLine)
{
	const auto p = bims::test::tmpPath("bims_test_common", "undefined_var.ini");
	std::ofstream(p) << "[a]\nx = ${UNDEFINED_BIMS_VAR}\n";
	const auto e = errorOf<bims::ConfigError>([&] { bims::openIniFile(p); });
	EXPECT_EQ(e.rfind(p + ": ", 0), 0u) << e;
	EXPECT_NE(e.find("UNDEFINED_BIMS_VAR"), std::string::npos) << e;
	EXPECT_EQ(e.find("backtrace"), std::string::npos) << e;
	EXPECT_EQ(e.find('\n'), std::string::npos) << e;
	// @define works as MRPT reads it
	const auto q = bims::test::tmpPath("bims_test_common", "define_var.ini");
	std::ofstream(q) << "@define V 0.25\n[a]\nx = ${V}\n";
	const auto cfg = bims::openIniFile(q);
	EXPECT_DOUBLE_EQ(cfg->read_double("a", "x", 0), 0.25);
}
