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
std::string slurp(const std::string& p)
{
	std::ifstream f(p);
	std::stringstream s;
	s << f.rdbuf();
	return s.str();
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
	EXPECT_EQ(slurp(d + "/target.txt"), "precious");
	EXPECT_FALSE(fs::is_symlink(fs::symlink_status(d + "/out.txt")));
	EXPECT_EQ(slurp(d + "/out.txt"), "new");
	// the same for a streamed file prepared with replaceSymlink
	fs::create_symlink(d + "/target.txt", d + "/streamed.txt");
	bims::replaceSymlink(d + "/streamed.txt");
	std::ofstream(d + "/streamed.txt") << "new";
	EXPECT_EQ(slurp(d + "/target.txt"), "precious");
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
	EXPECT_EQ(slurp(d + "/out.rawlog"), "old");
	{
		bims::PartialFile p(d + "/out.rawlog");
		std::ofstream(p.path()) << "whole";
		p.commit();
	}
	EXPECT_EQ(slurp(d + "/out.rawlog"), "whole");
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
	EXPECT_EQ(slurp(path).back(), '\n');
}
