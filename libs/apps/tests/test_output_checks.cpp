// The programs' output checks (output_checks.h): outputs never alias
// inputs, an output folder holding an earlier run is refused unless
// --overwrite.
#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace
{
std::string fresh(const std::string& name)
{
	return bims::test::freshTmpDir("bims_test_apps", name);
}

/** The message of the UsageError that \a f throws ("" if none). */
template <class F>
std::string usageError(F f)
{
	try
	{
		f();
	}
	catch (const bims::UsageError& e)
	{
		return e.what();
	}
	return "";
}
}  // namespace

TEST(OutputChecks, AnOutputThatIsAnInputIsRefusedNamingBoth)
{
	const auto d = fresh("alias_same");
	const std::string in = d + "/in.rawlog";
	std::ofstream(in) << "x";
	const auto e = usageError(
	    [&] {
		    bims::checkOutputsSpareInputs({"", in}, {d + "/./in.rawlog"});
	    });
	EXPECT_NE(e.find("would overwrite the input " + in), std::string::npos)
	    << e;
	EXPECT_NE(e.find(d + "/./in.rawlog"), std::string::npos) << e;
	// through a symbolic link to the input
	fs::create_symlink(in, d + "/link.rawlog");
	EXPECT_NE(
	    usageError(
	        [&] { bims::checkOutputsSpareInputs({in}, {d + "/link.rawlog"}); }),
	    "");
}

TEST(OutputChecks, AnOutputFolderHoldingAnInputIsRefused)
{
	const auto d = fresh("alias_folder");
	fs::create_directories(d + "/out/sub");
	const std::string in = d + "/out/sub/segmented.rawlog";
	std::ofstream(in) << "x";
	const auto e =
	    usageError([&] { bims::checkOutputsSpareInputs({in}, {d + "/out"}); });
	EXPECT_NE(e.find("output folder " + d + "/out contains the input " + in),
	          std::string::npos)
	    << e;
	// a sibling with a common prefix is not inside
	EXPECT_EQ(
	    usageError(
	        [&] {
		        bims::checkOutputsSpareInputs({in}, {d + "/ou", d + "/out2"});
	        }),
	    "");
	// an output inside an input folder is allowed (import-tum -o FOLDER/x)
	EXPECT_EQ(usageError(
	              [&] {
		              bims::checkOutputsSpareInputs({d + "/out"},
		                                            {d + "/out/new.rawlog"});
	              }),
	          "");
}

TEST(OutputChecks, AnEmptyOutputIsRefused)
{
	const auto e =
	    usageError([] { bims::checkOutputsSpareInputs({"a.rawlog"}, {""}); });
	EXPECT_NE(e.find("output path is empty"), std::string::npos) << e;
}

TEST(OutputChecks, AFolderOfAnEarlierRunIsRefusedThenClearedOfItsFilesOnly)
{
	const std::string d = fresh("earlier_run");
	const bims::OutputFolderLayout layout{{"metrics.json", "trajectory.txt"},
	                                      {{"masks", ".png"}, {"", ".png"}}};
	// nothing of a run: a missing folder, an empty one, other files
	EXPECT_EQ(bims::prepareOutputFolder(d + "/none", layout, false), 0u);
	fs::create_directories(d + "/out/masks");
	std::ofstream(d + "/out/notes.txt") << "mine";
	std::ofstream(d + "/out/masks/readme.txt") << "mine";
	std::ofstream(d + "/out/masks/x000001.png") << "mine";  // not a number
	std::ofstream(d + "/out/plot.png") << "mine";
	EXPECT_EQ(bims::prepareOutputFolder(d + "/out", layout, false), 0u);
	// an earlier run: refused naming the folder, a file and the flag
	std::ofstream(d + "/out/metrics.json") << "{}";
	std::ofstream(d + "/out/trajectory.txt.partial") << "";
	std::ofstream(d + "/out/masks/000001.png") << "";
	std::ofstream(d + "/out/masks/000002.png.partial") << "";
	std::ofstream(d + "/out/1548339824.89375.png") << "";
	fs::create_directories(d + "/out/other");
	std::ofstream(d + "/out/other/000001.png") << "mine";  // not in layout
	EXPECT_EQ(bims::earlierOutputs(d + "/out", layout).size(), 5u);
	try
	{
		bims::prepareOutputFolder(d + "/out", layout, false);
		FAIL() << "not refused";
	}
	catch (const bims::UsageError& e)
	{
		const std::string m = e.what();
		EXPECT_NE(m.find(d + "/out: holds the outputs of an earlier run (5 "
		                     "files, e.g. 1548339824.89375.png); give "
		                     "--overwrite"),
		          std::string::npos)
		    << m;
	}
	EXPECT_TRUE(fs::exists(d + "/out/metrics.json"));
	// --overwrite: those five go, everything else stays
	EXPECT_EQ(bims::prepareOutputFolder(d + "/out", layout, true), 5u);
	EXPECT_TRUE(bims::earlierOutputs(d + "/out", layout).empty());
	for (const char* f : {"notes.txt", "masks/readme.txt", "masks/x000001.png",
	                      "plot.png", "other/000001.png"})
		EXPECT_TRUE(fs::exists(d + "/out/" + f)) << f;
	// a per-frame folder left empty is removed
	fs::remove(d + "/out/masks/readme.txt");
	fs::remove(d + "/out/masks/x000001.png");
	std::ofstream(d + "/out/masks/000003.png") << "";
	EXPECT_EQ(bims::prepareOutputFolder(d + "/out", layout, true), 1u);
	EXPECT_FALSE(fs::exists(d + "/out/masks"));
}

TEST(OutputChecks, OverwriteRemovesALinkOfTheLayoutNotItsTarget)
{
	const std::string d = fresh("earlier_link");
	fs::create_directories(d + "/out");
	std::ofstream(d + "/precious.txt") << "precious";
	fs::create_symlink(d + "/precious.txt", d + "/out/metrics.json");
	const bims::OutputFolderLayout layout{{"metrics.json"}, {}};
	EXPECT_THROW(bims::prepareOutputFolder(d + "/out", layout, false),
	             bims::UsageError);
	EXPECT_EQ(bims::prepareOutputFolder(d + "/out", layout, true), 1u);
	EXPECT_FALSE(fs::is_symlink(fs::symlink_status(d + "/out/metrics.json")));
	EXPECT_TRUE(fs::exists(d + "/precious.txt"));
}
