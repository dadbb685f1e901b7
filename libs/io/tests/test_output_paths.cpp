// The output rule of every library: created files replace symbolic links,
// whole files appear only once complete (the programs' checks of outputs
// against inputs: libs/apps/tests/test_output_checks.cpp).
#include <bims/io/output_paths.h>
#include <gtest/gtest.h>

#include <bims_test/file_size_limit.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <functional>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <bims_test/tmp_dir.h>
#include "bims_test/text.h"

namespace fs = std::filesystem;
using bims::test::tmpPath;

namespace
{
std::string fresh(const std::string& name)
{
	const std::string d = tmpPath("bims_test_io", name);
	fs::remove_all(d);
	fs::create_directories(d);
	return d;
}
}  // namespace

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
	const auto onlyOut = [&]
	{
		std::vector<std::string> names;
		for (const auto& e : fs::directory_iterator(d))
			names.push_back(e.path().filename().string());
		EXPECT_EQ(names, std::vector<std::string>{"out.rawlog"});
	};
	{
		bims::PartialFile p(d + "/out.rawlog");
		// OUT.PID-TAG.partial: a name of this run's own
		const std::string name = fs::path(p.path()).filename().string();
		EXPECT_EQ(
		    name.rfind("out.rawlog." + std::to_string(::getpid()) + "-", 0), 0u)
		    << name;
		EXPECT_EQ(bims::partialTarget(name), "out.rawlog");
		EXPECT_TRUE(fs::exists(p.path()));
		std::ofstream(p.path()) << "half";
		// dropped without commit: an error on the way
	}
	onlyOut();
	EXPECT_EQ(bims::test::fileText(d + "/out.rawlog"), "old");
	{
		bims::PartialFile p(d + "/out.rawlog");
		std::ofstream(p.path()) << "whole";
		p.commit();
	}
	EXPECT_EQ(bims::test::fileText(d + "/out.rawlog"), "whole");
	onlyOut();
}

// Issue 55, item 11: two runs writing one output at once wrote into one
// OUT.partial, a mix of both; each now has its own, and a run's set of
// files is put in place together.
TEST(OutputPaths, TwoWritersOfOneOutputNeverShareAPartialFile)
{
	const auto d = fresh("two_writers");
	bims::PartialFile a(d + "/out.rawlog"), b(d + "/out.rawlog");
	EXPECT_NE(a.path(), b.path());
	bims::PartialFile aRef(d + "/out_ref.txt"), bRef(d + "/out_ref.txt");
	bims::writePartialFile(a, "run a");
	bims::writePartialFile(b, "run b");
	bims::writePartialFile(aRef, "ref a");
	bims::writePartialFile(bRef, "ref b");
	bims::commitTogether({&b, &bRef});
	bims::commitTogether({&a, &aRef});
	EXPECT_EQ(bims::test::fileText(d + "/out.rawlog"), "run a");
	EXPECT_EQ(bims::test::fileText(d + "/out_ref.txt"), "ref a");
	EXPECT_EQ(
	    std::distance(fs::directory_iterator(d), fs::directory_iterator{}), 2);
	// the names partialTarget() takes, and those it does not
	EXPECT_EQ(bims::partialTarget("x.png.partial"), "x.png");
	EXPECT_EQ(bims::partialTarget("x.png.123-0123abcd.partial"), "x.png");
	EXPECT_EQ(bims::partialTarget("x.png.12a-0123abcd.partial"),
	          "x.png.12a-0123abcd");
	EXPECT_EQ(bims::partialTarget("x.png"), "");
}

// Issue 55, item 1: an output that is a FIFO or a device was replaced by
// a regular file (as root, -o /dev/null would destroy /dev/null). Refused,
// naming it; a symbolic link to a device is replaced, never its target.
TEST(OutputPaths, AFifoOrADeviceAsOutputIsRefusedNeverReplaced)
{
	const auto d = fresh("special");
	const std::string fifo = d + "/out.rawlog";
	if (::mkfifo(fifo.c_str(), 0600) != 0)
		GTEST_SKIP() << "mkfifo refused here: " << std::strerror(errno);
	const auto refused = [&](const std::function<void()>& f)
	{
		try
		{
			f();
		}
		catch (const std::runtime_error& e)
		{
			return std::string(e.what());
		}
		return std::string("nothing thrown");
	};
	for (const auto& e :
	     {refused([&] { bims::PartialFile p(fifo); }),
	      refused([&] { bims::writeFileAtomically(fifo, "x"); }),
	      refused([&] { bims::AppendFile f(fifo); }),
	      refused([&] { bims::checkOutputFilesWritable({fifo}); })})
		EXPECT_NE(e.find(fifo + ": is a FIFO (named pipe), not a regular file"),
		          std::string::npos)
		    << e;
	EXPECT_TRUE(fs::is_fifo(fifo));
	EXPECT_EQ(
	    std::distance(fs::directory_iterator(d), fs::directory_iterator{}), 1);
	// made a FIFO between the start and the commit: still refused
	{
		bims::PartialFile p(d + "/late.rawlog");
		ASSERT_EQ(::mkfifo((d + "/late.rawlog").c_str(), 0600), 0);
		EXPECT_THROW(p.commit(), std::runtime_error);
		EXPECT_TRUE(fs::is_fifo(d + "/late.rawlog"));
	}
	// a link to /dev/null: the link is replaced, /dev/null stays a device
	struct stat st;
	if (::stat("/dev/null", &st) == 0 && S_ISCHR(st.st_mode))
	{
		fs::create_symlink("/dev/null", d + "/null.rawlog");
		bims::writeFileAtomically(d + "/null.rawlog", "x");
		EXPECT_TRUE(
		    fs::is_regular_file(fs::symlink_status(d + "/null.rawlog")));
		EXPECT_TRUE(fs::is_character_file("/dev/null"));
	}
}

TEST(OutputPaths, APartialFileOfNoPathIsAPlainError)
{
	// a library's error (the programs refuse an empty output before:
	// checkOutputsSpareInputs)
	EXPECT_THROW(bims::PartialFile(""), std::invalid_argument);
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
	// with the manifest of what it holds
	EXPECT_EQ(bims::manifestFiles(d + "/x_gt"),
	          (std::vector<std::string>{"groundtruth.txt", "masks/000000.png",
	                                    "masks/000001.png"}));
	// dropped (an error on the way): the earlier folder as it was
	{
		bims::PartialDir gt(d + "/x_gt", layout);
		write(gt.path() + "/groundtruth.txt", "two");
	}
	EXPECT_EQ(bims::test::fileText(d + "/x_gt/groundtruth.txt"), "one");
	EXPECT_FALSE(fs::exists(d + "/x_gt.partial"));
	// over an earlier run with a user's files: the run's files replaced
	// (its extra mask gone), the user's kept, even one named as the run
	// names its masks (only what the earlier manifest lists goes)
	write(d + "/x_gt/notes.txt", "mine");
	write(d + "/x_gt/masks/000009.png", "my mask");
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
	EXPECT_EQ(bims::test::fileText(d + "/x_gt/masks/000009.png"), "my mask");
	EXPECT_EQ(
	    bims::manifestFiles(d + "/x_gt"),
	    (std::vector<std::string>{"groundtruth.txt", "masks/000000.png"}));
	EXPECT_FALSE(fs::exists(d + "/x_gt.partial"));
	// a folder an older bims wrote (no manifest): the layout's files go
	write(d + "/o_gt/groundtruth.txt", "old");
	write(d + "/o_gt/masks/000003.png", "old mask");
	write(d + "/o_gt/notes.txt", "mine");
	{
		bims::PartialDir gt(d + "/o_gt", layout);
		write(gt.path() + "/groundtruth.txt", "new");
		gt.commit();
	}
	EXPECT_EQ(bims::test::fileText(d + "/o_gt/groundtruth.txt"), "new");
	EXPECT_FALSE(fs::exists(d + "/o_gt/masks"));
	EXPECT_EQ(bims::test::fileText(d + "/o_gt/notes.txt"), "mine");
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
