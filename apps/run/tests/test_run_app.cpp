// bims-run as a program: what it refuses before any work, and what it never
// does to files it did not create.
#include <bims_test/run_command.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace
{
const std::string kBin = BIMS_BIN_DIR;
const std::string kSrc = BIMS_SOURCE_DIR;
const std::string kConfig = kSrc + "/config/default.ini";
const std::string kSample = kSrc + "/rawlogs/pendulum_slow.rawlog";

/** bims-run ARGS: exit code and output. */
bims::test::CommandResult run(const std::string& args)
{
	return bims::test::runCommand(kBin + "/bims-run " + args);
}
std::string tmpDir(const std::string& name)
{
	const auto d = fs::temp_directory_path() / "bims_test_run_app" / name;
	fs::remove_all(d);
	fs::create_directories(d);
	return d.string();
}
std::string slurp(const std::string& p)
{
	std::ifstream f(p, std::ios::binary);
	std::stringstream s;
	s << f.rdbuf();
	return s.str();
}
std::string q(const std::string& s)
{
	return "'" + s + "'";
}
}  // namespace

TEST(RunApp, AnInputInsideTheOutputFolderIsRefusedUntouched)
{
	const auto d = tmpDir("input_in_output");
	const std::string in = d + "/segmented.rawlog";
	fs::copy_file(kSample, in);
	const auto before = fs::file_size(in);
	const auto r = run(q(kConfig) + " " + q(in) + " -o " + q(d) + " -q");
	EXPECT_EQ(r.code, 2) << r.out;
	EXPECT_NE(r.out.find("output folder " + d + " contains the input " + in),
	          std::string::npos)
	    << r.out;
	EXPECT_EQ(fs::file_size(in), before);
	EXPECT_FALSE(fs::exists(d + "/trajectory.txt"));
	// the config counts as an input too
	const auto r2 = run(q(kConfig) + " " + q(kSample) + " -o " +
	                    q(kSrc + "/config") + " -q");
	EXPECT_EQ(r2.code, 2) << r2.out;
	EXPECT_NE(r2.out.find("contains the input " + kConfig), std::string::npos)
	    << r2.out;
}

TEST(RunApp, AnEmptyOutputFolderIsRefused)
{
	const auto r = run(q(kConfig) + " " + q(kSample) + " -o '' -q");
	EXPECT_EQ(r.code, 2) << r.out;
	EXPECT_NE(r.out.find("output path is empty"), std::string::npos) << r.out;
	EXPECT_EQ(r.out.find("outputs in"), std::string::npos) << r.out;
}

TEST(RunApp, SymlinkedOutputFilesAreReplacedNotFollowed)
{
	const auto d = tmpDir("symlinks");
	const std::string out = d + "/out";
	fs::create_directories(out + "/masks");
	fs::create_directories(out + "/moving_voxels");
	std::ofstream(d + "/precious.txt") << "precious";
	for (const char* f :
	     {"trajectory.txt", "frames.csv", "metrics.json", "segmented.rawlog",
	      "static_map.ply", "masks/000001.png", "moving_voxels/000001.ply"})
		fs::create_symlink(d + "/precious.txt", out + "/" + f);
	const auto r = run(q(kConfig) + " " + q(kSample) + " -o " + q(out) +
	                   " --frames 0:2 -q");
	ASSERT_EQ(r.code, 0) << r.out;
	EXPECT_EQ(slurp(d + "/precious.txt"), "precious");
	for (const char* f :
	     {"trajectory.txt", "frames.csv", "metrics.json", "segmented.rawlog",
	      "static_map.ply", "masks/000001.png", "moving_voxels/000001.ply"})
	{
		EXPECT_FALSE(fs::is_symlink(fs::symlink_status(out + "/" + f))) << f;
		EXPECT_GT(fs::file_size(out + "/" + f), 0u) << f;
	}
}
