// The one output rule: outputs never alias inputs, created files replace
// symbolic links, whole files appear only once complete.
#include <bims/common/app.h>
#include <bims/common/output_paths.h>
#include <gtest/gtest.h>

#include <bims_test/file_size_limit.h>
#include <unistd.h>

#include <csignal>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "bims_test/text.h"
#include "tmp_path.h"

namespace fs = std::filesystem;
using bims::test::tmpPath;

namespace
{
std::string fresh(const std::string& name)
{
	const std::string d = tmpPath(name);
	fs::remove_all(d);
	fs::create_directories(d);
	return d;
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

TEST(OutputPaths, AnOutputThatIsAnInputIsRefusedNamingBoth)
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

TEST(OutputPaths, AnOutputFolderHoldingAnInputIsRefused)
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

TEST(OutputPaths, AnEmptyOutputIsRefused)
{
	const auto e =
	    usageError([] { bims::checkOutputsSpareInputs({"a.rawlog"}, {""}); });
	EXPECT_NE(e.find("output path is empty"), std::string::npos) << e;
}

TEST(OutputPaths, AWrittenFileReplacesASymlinkAndLeavesItsTarget)
{
	const auto d = fresh("symlink");
	std::ofstream(d + "/target.txt") << "precious";
	fs::create_symlink(d + "/target.txt", d + "/out.txt");
	bims::writeFileAtomically(d + "/out.txt", "new");
	EXPECT_EQ(bims::test::fileText(d + "/target.txt"), "precious");
	EXPECT_FALSE(fs::is_symlink(fs::symlink_status(d + "/out.txt")));
	EXPECT_EQ(bims::test::fileText(d + "/out.txt"), "new");
	// the same for a streamed file prepared with replaceSymlink
	fs::create_symlink(d + "/target.txt", d + "/streamed.txt");
	bims::replaceSymlink(d + "/streamed.txt");
	std::ofstream(d + "/streamed.txt") << "new";
	EXPECT_EQ(bims::test::fileText(d + "/target.txt"), "precious");
	EXPECT_THROW(bims::replaceSymlink(d), std::runtime_error);  // a folder
}

TEST(OutputPaths, APartialFileAppearsOnlyWhenCommitted)
{
	const auto d = fresh("partial");
	std::ofstream(d + "/out.rawlog") << "old";
	{
		bims::PartialFile p(d + "/out.rawlog");
		EXPECT_EQ(p.path(), d + "/out.rawlog.partial");
		std::ofstream(p.path()) << "half";
		// dropped without commit: an error on the way
	}
	EXPECT_FALSE(fs::exists(d + "/out.rawlog.partial"));
	EXPECT_EQ(bims::test::fileText(d + "/out.rawlog"), "old");
	{
		bims::PartialFile p(d + "/out.rawlog");
		std::ofstream(p.path()) << "whole";
		p.commit();
	}
	EXPECT_EQ(bims::test::fileText(d + "/out.rawlog"), "whole");
	EXPECT_FALSE(fs::exists(d + "/out.rawlog.partial"));
}

TEST(OutputPaths, AFailedAppendLeavesTheFileAtItsLastWholeRecord)
{
	// a child limited to 100-byte files (SIGXFSZ ignored: writes fail with
	// EFBIG, as on a full disk) appends 18-byte records
	const auto d = fresh("append_limit");
	const std::string path = d + "/records.txt";
	const int code = bims::test::exitOfChildWithFileSizeLimit(
	    100,
	    [&]
	    {
		    try
		    {
			    bims::AppendFile f(path);
			    for (int i = 0; i < 100; i++) f.append("record 0123456789\n");
			    return 0;
		    }
		    catch (const std::exception& e)
		    {
			    const std::string m = e.what();
			    return m.find(path + ": write failed: File too large") == 0 ? 3
			                                                                : 4;
		    }
	    });
	EXPECT_EQ(code, 3);
	EXPECT_EQ(fs::file_size(path), 90u);  // 5 whole records
	EXPECT_EQ(bims::test::fileText(path).back(), '\n');
}

TEST(OutputPaths, AFolderOfAnEarlierRunIsRefusedThenClearedOfItsFilesOnly)
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

TEST(OutputPaths, OverwriteRemovesALinkOfTheLayoutNotItsTarget)
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

// A folder output appears only whole: written aside, put in place by
// commit() (an earlier run's files replaced, others kept), dropped without.
TEST(OutputPaths, APartialDirIsPutInPlaceWholeOrNotAtAll)
{
	const std::string d = fresh("partial_dir");
	const bims::OutputFolderLayout layout{{"groundtruth.txt"},
	                                      {{"masks", ".png"}}};
	const auto write = [](const std::string& p, const std::string& text)
	{
		fs::create_directories(fs::path(p).parent_path());
		std::ofstream(p) << text;
	};
	// into nothing: renamed
	{
		bims::PartialDir gt(d + "/x_gt", layout);
		EXPECT_EQ(gt.path(), d + "/x_gt.partial");
		write(gt.path() + "/groundtruth.txt", "one");
		write(gt.path() + "/masks/000000.png", "m0");
		write(gt.path() + "/masks/000001.png", "m1");
		EXPECT_FALSE(fs::exists(d + "/x_gt"));
		gt.commit();
	}
	EXPECT_EQ(bims::test::fileText(d + "/x_gt/groundtruth.txt"), "one");
	EXPECT_FALSE(fs::exists(d + "/x_gt.partial"));
	// dropped (an error on the way): the earlier folder as it was
	{
		bims::PartialDir gt(d + "/x_gt", layout);
		write(gt.path() + "/groundtruth.txt", "two");
	}
	EXPECT_EQ(bims::test::fileText(d + "/x_gt/groundtruth.txt"), "one");
	EXPECT_FALSE(fs::exists(d + "/x_gt.partial"));
	// over an earlier run with a user's file: the run's files replaced
	// (its extra mask gone), the user's kept
	write(d + "/x_gt/notes.txt", "mine");
	write(d + "/x_gt.partial/stale.png", "a killed run's");
	{
		bims::PartialDir gt(d + "/x_gt", layout);
		EXPECT_FALSE(fs::exists(gt.path() + "/stale.png"));
		write(gt.path() + "/groundtruth.txt", "three");
		write(gt.path() + "/masks/000000.png", "n0");
		gt.commit();
	}
	EXPECT_EQ(bims::test::fileText(d + "/x_gt/groundtruth.txt"), "three");
	EXPECT_EQ(bims::test::fileText(d + "/x_gt/masks/000000.png"), "n0");
	EXPECT_FALSE(fs::exists(d + "/x_gt/masks/000001.png"));
	EXPECT_EQ(bims::test::fileText(d + "/x_gt/notes.txt"), "mine");
	EXPECT_FALSE(fs::exists(d + "/x_gt.partial"));
	// a symbolic link at the name: replaced, its target untouched
	write(d + "/elsewhere/groundtruth.txt", "theirs");
	fs::create_directory_symlink(d + "/elsewhere", d + "/y_gt");
	{
		bims::PartialDir gt(d + "/y_gt", layout);
		write(gt.path() + "/groundtruth.txt", "ours");
		gt.commit();
	}
	EXPECT_FALSE(fs::is_symlink(d + "/y_gt"));
	EXPECT_EQ(bims::test::fileText(d + "/y_gt/groundtruth.txt"), "ours");
	EXPECT_EQ(bims::test::fileText(d + "/elsewhere/groundtruth.txt"), "theirs");
}

TEST(OutputPaths, GroundTruthDirDropsTheRawlogExtensions)
{
	EXPECT_EQ(bims::groundTruthDirFor("a/b.rawlog"), "a/b_gt");
	EXPECT_EQ(bims::groundTruthDirFor("a/b.rawlog.gz"), "a/b_gt");
	EXPECT_EQ(bims::groundTruthDirFor("b.gz"), "b_gt");
	EXPECT_EQ(bims::groundTruthDirFor("b.bin"), "b.bin_gt");
}
