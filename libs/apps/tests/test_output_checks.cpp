// The programs' output checks (output_checks.h): outputs never alias
// inputs, an output folder holding an earlier run is refused unless
// --overwrite.
#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>
#include <bims_test/error_of.h>
#include <bims_test/text.h>
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
std::string usageError(const std::function<void()>& f)
{
	return bims::test::errorOf<bims::UsageError>(f);
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
	// --overwrite: those five go (the earlier run's manifest lists them),
	// everything else stays
	{
		bims::OutputManifest m(d + "/out", "test");
		for (const char* f :
		     {"metrics.json", "trajectory.txt", "masks/000001.png",
		      "masks/000002.png", "1548339824.89375.png"})
			m.file(f);
	}
	EXPECT_EQ(bims::earlierOutputs(d + "/out", layout).size(), 6u);
	EXPECT_EQ(bims::prepareOutputFolder(d + "/out", layout, true), 5u);
	EXPECT_TRUE(bims::earlierOutputs(d + "/out", layout).empty());
	EXPECT_FALSE(fs::exists(d + "/out/" + bims::kOutputManifest));
	for (const char* f : {"notes.txt", "masks/readme.txt", "masks/x000001.png",
	                      "plot.png", "other/000001.png"})
		EXPECT_TRUE(fs::exists(d + "/out/" + f)) << f;
	// a sub-folder its files leave empty is removed
	fs::remove(d + "/out/masks/readme.txt");
	fs::remove(d + "/out/masks/x000001.png");
	bims::OutputManifest(d + "/out", "test").file("masks/000003.png");
	std::ofstream(d + "/out/masks/000003.png") << "";
	EXPECT_EQ(bims::prepareOutputFolder(d + "/out", layout, true), 1u);
	EXPECT_FALSE(fs::exists(d + "/out/masks"));
}

// Issue 39: --overwrite deleted whatever had an output's name. It removes
// what the earlier run's manifest lists, and refuses, keeping everything,
// when a file at an output name is not in it (a user's, another program's,
// or a folder without a manifest).
TEST(OutputChecks, OverwriteRemovesOnlyWhatTheEarlierRunsManifestLists)
{
	const std::string d = fresh("manifest");
	const bims::OutputFolderLayout layout{{"metrics.json", "trajectory.txt"},
	                                      {{"masks", ".png"}}};
	fs::create_directories(d + "/out/masks");
	{
		bims::OutputManifest m(d + "/out", "test");
		std::ofstream(m.file("metrics.json")) << "{}";
		std::ofstream(m.file("masks/000000.png")) << "run";
		m.file("masks/000000.png");  // listed once
		m.file("trajectory.txt");    // listed, never written (killed)
	}
	EXPECT_EQ(bims::manifestFiles(d + "/out"),
	          (std::vector<std::string>{"metrics.json", "masks/000000.png",
	                                    "trajectory.txt"}));
	std::ofstream(d + "/out/masks/000001.png") << "mine";
	const auto e = usageError(
	    [&] { bims::prepareOutputFolder(d + "/out", layout, true); });
	EXPECT_NE(e.find(d + "/out: --overwrite removes only the files an "
	                     "earlier run's manifest (bims-manifest.txt) lists; "
	                     "these are not in it and are kept: masks/000001.png; "
	                     "remove them yourself"),
	          std::string::npos)
	    << e;
	for (const char* f : {"metrics.json", "masks/000000.png",
	                      "masks/000001.png", "bims-manifest.txt"})
		EXPECT_TRUE(fs::exists(d + "/out/" + f)) << f;  // nothing removed
	fs::remove(d + "/out/masks/000001.png");
	EXPECT_EQ(bims::prepareOutputFolder(d + "/out", layout, true), 2u);
	EXPECT_FALSE(fs::exists(d + "/out/masks"));
	EXPECT_FALSE(fs::exists(d + "/out/bims-manifest.txt"));
	// no manifest: nothing is the earlier run's
	std::ofstream(d + "/out/metrics.json") << "{}";
	const auto none = usageError(
	    [&] { bims::prepareOutputFolder(d + "/out", layout, true); });
	EXPECT_NE(none.find("these are not in one (there is none) and are kept: "
	                    "metrics.json"),
	          std::string::npos)
	    << none;
	EXPECT_TRUE(fs::exists(d + "/out/metrics.json"));
	// a manifest naming a path out of the folder is no manifest of bims's
	std::ofstream(d + "/out/bims-manifest.txt") << "metrics.json\n../x\n";
	std::ofstream(d + "/x") << "precious";
	const auto out = usageError(
	    [&] { bims::prepareOutputFolder(d + "/out", layout, true); });
	EXPECT_NE(out.find("bims-manifest.txt:2: ../x is outside the folder"),
	          std::string::npos)
	    << out;
	EXPECT_TRUE(fs::exists(d + "/x"));
	EXPECT_TRUE(fs::exists(d + "/out/metrics.json"));
}

// A manifest's file below a folder that is now a link to elsewhere is
// never reached through the link: the link goes, its target stays whole.
TEST(OutputChecks, AManifestIsNeverFollowedThroughALinkedFolder)
{
	const std::string d = fresh("manifest_link");
	fs::create_directories(d + "/keep");
	fs::create_directories(d + "/out");
	std::ofstream(d + "/keep/000000.png") << "x";
	bims::OutputManifest(d + "/out", "test").file("masks/000000.png");
	fs::create_directory_symlink(d + "/keep", d + "/out/masks");
	const bims::OutputFolderLayout layout{{}, {{"masks", ".png"}}};
	EXPECT_EQ(bims::prepareOutputFolder(d + "/out", layout, true), 1u);
	EXPECT_FALSE(fs::exists(fs::symlink_status(d + "/out/masks")));
	EXPECT_EQ(bims::test::fileText(d + "/keep/000000.png"), "x");
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
