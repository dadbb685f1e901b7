#include <bims/io/rawlog.h>
#include <gtest/gtest.h>

#include <bims_test/file_size_limit.h>
#include <bims_test/incompressible_rawlog.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/system/filesystem.h>

#include <bims_test/tmp_dir.h>

#include <filesystem>
#include <fstream>

namespace
{
using bims::test::tmpPath;

void writeImus(const std::string& path, int n, int gz)
{
	bims::RawlogWriter w(path, gz);
	for (int i = 0; i < n; i++)
	{
		mrpt::obs::CObservationIMU imu;
		imu.sensorLabel = "IMU";
		imu.timestamp = mrpt::Clock::fromDouble(100.0 + i * 0.01);
		imu.set(mrpt::obs::IMU_WZ, 0.1 * i);
		w.write(imu);
	}
	EXPECT_EQ(w.written(), static_cast<size_t>(n));
}
}  // namespace

TEST(Rawlog, RoundTripPlainAndGzip)
{
	for (int gz : {0, 1})
	{
		const auto p =
		    tmpPath("bims_test_io", "rt" + std::to_string(gz) + ".rawlog");
		writeImus(p, 20, gz);
		bims::RawlogReader r(p);
		int n = 0;
		while (auto o = r.next())
		{
			auto imu = std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o);
			ASSERT_TRUE(imu);
			EXPECT_DOUBLE_EQ(imu->get(mrpt::obs::IMU_WZ), 0.1 * n);
			n++;
		}
		EXPECT_EQ(n, 20);
	}
}

TEST(Rawlog, MissingFileIsAClearError)
{
	try
	{
		bims::RawlogReader r(tmpPath("bims_test_io", "does_not_exist.rawlog"));
		FAIL() << "no exception";
	}
	catch (const bims::RawlogError& e)
	{
		EXPECT_NE(std::string(e.what()).find("does_not_exist.rawlog: no such"),
		          std::string::npos);
	}
}

// Issue 55: an empty file read as a rawlog of nothing (bims.read_rawlog
// yielded nothing without an error); it is no rawlog, not even a gzip
// header: an error naming it, for every reader.
TEST(Rawlog, AnEmptyFileIsNotARawlog)
{
	const auto p = tmpPath("bims_test_io", "empty.rawlog");
	std::ofstream(p).close();
	try
	{
		bims::RawlogReader r(p);
		FAIL() << "no exception";
	}
	catch (const bims::RawlogError& e)
	{
		EXPECT_EQ(std::string(e.what()),
		          p + ": an empty file (0 bytes), not a rawlog");
	}
}

TEST(Rawlog, TruncatedFileIsAnErrorNamingFileAndEntry)
{
	const auto p = tmpPath("bims_test_io", "trunc.rawlog");
	writeImus(p, 10, 0);
	const auto size = std::filesystem::file_size(p);
	std::filesystem::resize_file(p, size - 7);
	bims::RawlogReader r(p);
	int n = 0;
	try
	{
		while (r.next()) n++;
		FAIL() << "truncation not detected";
	}
	catch (const bims::RawlogError& e)
	{
		const std::string msg = e.what();
		EXPECT_NE(
		    msg.find("trunc.rawlog: truncated or corrupt rawlog at entry 9"),
		    std::string::npos)
		    << msg;
	}
	EXPECT_EQ(n, 9);
}

TEST(Rawlog, GarbageFileIsAnError)
{
	const auto p = tmpPath("bims_test_io", "garbage.rawlog");
	{
		std::ofstream f(p, std::ios::binary);
		for (int i = 0; i < 1000; i++)
			f.put(static_cast<char>((i * 37) & 0xff));
	}
	bims::RawlogReader r(p);
	EXPECT_THROW(
	    {
		    while (r.next())
		    {
		    }
	    },
	    bims::RawlogError);
}

TEST(Rawlog, ImagesDirectoryKeepsTheSlash)
{
	EXPECT_EQ(bims::rawlogImagesDirectory("dir/foo.rawlog"), "dir/foo_Images");
	EXPECT_EQ(bims::rawlogImagesDirectory("foo.rawlog"), "foo_Images");
}

TEST(Rawlog, AGzipRawlogWhoseTailFailsAtCloseIsAnError)
{
	// 15 IMU observations with 400 random bytes of label each (6 kB that do
	// not compress: all of it still in zlib's buffers at close) in a child
	// limited to 1000-byte files (SIGXFSZ ignored: the write fails with
	// EFBIG, as on a full disk): close() must report it (MRPT's gzip stream
	// did not)
	const auto p = tmpPath("bims_test_io", "gz_close_limit.rawlog");
	const int code = bims::test::writeIncompressibleOnAFullDisk(p, 9, 1000, 15,
	                                                            400, p + ": ");
	std::filesystem::remove(p);
	EXPECT_EQ(code, 3);
}

TEST(Rawlog, DataBytesOfPlainAndGzipFilesAreWhatTheReaderReads)
{
	// the progress line's share of the input read (bims-run)
	for (int gz : {0, 6})
	{
		const auto p =
		    tmpPath("bims_test_io", "bytes" + std::to_string(gz) + ".rawlog");
		writeImus(p, 50, gz);
		const uint64_t data = bims::rawlogDataBytes(p);
		if (gz)
		{
			EXPECT_GT(data, std::filesystem::file_size(p));
		}
		bims::RawlogReader r(p);
		EXPECT_EQ(r.bytesRead(), 0u);
		uint64_t last = 0;
		while (r.next())
		{
			EXPECT_GT(r.bytesRead(), last);
			last = r.bytesRead();
		}
		EXPECT_EQ(last, data) << gz;
	}
	EXPECT_EQ(bims::rawlogDataBytes(tmpPath("bims_test_io", "no_such.rawlog")),
	          0u);
}

TEST(Rawlog, Count3DScansStopsAtTheLimitAndSkipsOtherLabels)
{
	const auto p = tmpPath("bims_test_io", "scans.rawlog");
	{
		bims::RawlogWriter w(p, 0);
		for (int i = 0; i < 6; i++)
		{
			mrpt::obs::CObservation3DRangeScan s;
			s.sensorLabel = i % 3 == 2 ? "OTHER" : "RGBD";
			s.timestamp = mrpt::Clock::fromDouble(100.0 + i);
			w.write(s);
		}
	}
	EXPECT_EQ(bims::count3DScans({p}, "", 100), 6u);
	EXPECT_EQ(bims::count3DScans({p}, "RGBD", 100), 4u);
	EXPECT_EQ(bims::count3DScans({p, p}, "RGBD", 100), 8u);
	EXPECT_EQ(bims::count3DScans({p, p}, "", 3), 3u);
}
