// The input-file rule (bims/common/input_file.h): only regular files are
// read, a FIFO or a device refused naming it (never waited on), a path that
// does not resolve named with its real reason; text read line by line
// with its line ends, a byte-order mark skipped, a line's length bounded.
#include <bims/common/input_file.h>
#include <bims_test/error_of.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace
{
namespace fs = std::filesystem;
using bims::test::errorOf;

std::vector<std::string> linesOf(const std::string& path, size_t maxLine = 64)
{
	bims::LineReader r(path, "test file", maxLine);
	std::vector<std::string> out;
	std::string line;
	while (r.next(line)) out.push_back(line);
	return out;
}

void write(const std::string& path, const std::string& bytes)
{
	std::ofstream(path, std::ios::binary) << bytes;
}
}  // namespace

TEST(InputFile, AFifoIsRefusedNamingItWithoutWaitingForAWriter)
{
	const auto d = bims::test::freshTmpDir("bims_test_input_file", "fifo");
	const std::string p = d + "/odometry.csv";
	if (::mkfifo(p.c_str(), 0600) != 0)
		GTEST_SKIP() << "mkfifo refused here: " << std::strerror(errno);
	// (without the rule, opening it blocks this test until its timeout)
	const auto e = errorOf([&] { bims::LineReader r(p, "CSV file"); });
	EXPECT_NE(e.find(p + ": cannot read CSV file: a FIFO (named pipe), not a "
	                     "regular file"),
	          std::string::npos)
	    << e;
	EXPECT_NE(bims::inputFileProblem(p).find("FIFO"), std::string::npos);
	EXPECT_NE(errorOf([&] { bims::checkInputFile(p, "video"); })
	              .find(p + ": cannot read video: a FIFO"),
	          std::string::npos);
}

TEST(InputFile, ADeviceIsRefusedBeforeAnythingIsRead)
{
	// /dev/zero only read from: it never ends
	struct stat st;
	if (::stat("/dev/zero", &st) != 0 || !S_ISCHR(st.st_mode))
		GTEST_SKIP() << "no character device /dev/zero here";
	const auto d = bims::test::freshTmpDir("bims_test_input_file", "device");
	fs::create_symlink("/dev/zero", d + "/imu.csv");
	const auto e =
	    errorOf([&] { bims::InputFile f(d + "/imu.csv", "IMU file"); });
	EXPECT_NE(e.find(d + "/imu.csv: cannot read IMU file: a character device, "
	                     "not a regular file"),
	          std::string::npos)
	    << e;
}

TEST(InputFile, APathThatDoesNotResolveIsNamedWithItsRealReason)
{
	const auto d = bims::test::freshTmpDir("bims_test_input_file", "paths");
	fs::create_symlink("b.png", d + "/a.png");
	fs::create_symlink("a.png", d + "/b.png");
	EXPECT_EQ(bims::inputFileProblem(d + "/a.png"),
	          "a symbolic link loop (too many levels of symbolic links)");
	fs::create_symlink("gone.png", d + "/dangling.png");
	EXPECT_EQ(bims::inputFileProblem(d + "/dangling.png"),
	          "a symbolic link to nothing (gone.png)");
	EXPECT_EQ(bims::inputFileProblem(d + "/none.png"), "no such file");
	EXPECT_EQ(bims::inputFileProblem(d), "a folder, not a file");
	write(d + "/ok.csv", "x\n");
	EXPECT_EQ(bims::inputFileProblem(d + "/ok.csv"), "");
	EXPECT_EQ(bims::InputFile(d + "/ok.csv", "x").size(), 2u);
}

TEST(LineReader, TakesEveryLineEndAndSkipsAByteOrderMark)
{
	const auto d = bims::test::freshTmpDir("bims_test_input_file", "ends");
	const std::vector<std::string> abc = {"a,1", "b,2", "c,3"};
	write(d + "/lf.csv", "a,1\nb,2\nc,3\n");
	write(d + "/crlf.csv", "a,1\r\nb,2\r\nc,3\r\n");
	write(d + "/cr.csv", "a,1\rb,2\rc,3\r");
	write(d + "/bom.csv",
	      "\xEF\xBB\xBF"
	      "a,1\nb,2\nc,3");
	EXPECT_EQ(linesOf(d + "/lf.csv"), abc);
	EXPECT_EQ(linesOf(d + "/crlf.csv"), abc);
	EXPECT_EQ(linesOf(d + "/cr.csv"), abc);
	EXPECT_EQ(linesOf(d + "/bom.csv"), abc);
	bims::LineReader r(d + "/bom.csv", "x");
	std::string line;
	ASSERT_TRUE(r.next(line));
	EXPECT_TRUE(r.hadByteOrderMark());
	EXPECT_EQ(r.lineNumber(), 1u);
	// empty lines are lines (numbered); an empty file has none
	write(d + "/empty_lines.csv", "\n\r\nx\r\r");
	EXPECT_EQ(linesOf(d + "/empty_lines.csv"),
	          (std::vector<std::string>{"", "", "x", ""}));
	write(d + "/empty.csv", "");
	EXPECT_TRUE(linesOf(d + "/empty.csv").empty());
	// a "\r\n" split across the reader's chunks is still one line end
	std::string big(64 * 1024 - 1, 'x');
	write(d + "/split.csv", big + "\r\ny\n");
	EXPECT_EQ(linesOf(d + "/split.csv", 128 * 1024),
	          (std::vector<std::string>{big, "y"}));
}

TEST(LineReader, ALineBeyondTheBoundIsAnErrorNamingFileAndLine)
{
	const auto d = bims::test::freshTmpDir("bims_test_input_file", "long");
	// 3 MB of zero bytes after two lines: the bound stops it, not memory
	write(d + "/zeros.csv", "a\nb\n" + std::string(3 << 20, '\0'));
	const auto e = errorOf([&] { linesOf(d + "/zeros.csv", 1000); });
	EXPECT_NE(e.find(d + "/zeros.csv:3: a line longer than 1000 bytes: not a "
	                     "test file"),
	          std::string::npos)
	    << e;
	// many lines are read one at a time (the bound is per line)
	std::string many;
	for (int i = 0; i < 20000; i++) many += "0123456789\n";
	write(d + "/many.csv", many);
	EXPECT_EQ(linesOf(d + "/many.csv", 16).size(), 20000u);
}
