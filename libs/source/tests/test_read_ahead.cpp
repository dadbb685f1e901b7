// The frame source's reading thread (internal class): order across files,
// errors in stream order, early stop.
#include <bims/io/rawlog.h>
#include <gtest/gtest.h>
#include <mrpt/obs/CObservationIMU.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "../src/read_ahead.h"

namespace fs = std::filesystem;
using bims::source::ReadAhead;

namespace
{
std::string tmpDir(const std::string& name)
{
	const auto d = fs::temp_directory_path() / "bims_test_read_ahead" / name;
	fs::remove_all(d);
	fs::create_directories(d);
	return d.string();
}

mrpt::obs::CObservationIMU::Ptr imu(int i)
{
	auto o = mrpt::obs::CObservationIMU::Create();
	o->sensorLabel = "IMU";
	o->timestamp = mrpt::Clock::fromDouble(1000.0 + 0.01 * i);
	o->set(mrpt::obs::IMU_X_ACC, 0.001 * i);
	return o;
}

/** A plain rawlog of n IMU samples numbered from first; with \a cut, half of
 * one more sample is appended (a truncated file). */
std::string imuRawlog(const std::string& path, int first, int n,
                      bool cut = false)
{
	{
		bims::RawlogWriter w(path, 0);
		for (int i = 0; i < n; i++) w.write(*imu(first + i));
	}
	if (cut)
	{
		const std::string one = path + ".one";
		{
			bims::RawlogWriter w(one, 0);
			w.write(*imu(first + n));
		}
		std::ifstream g(one, std::ios::binary);
		const std::string bytes((std::istreambuf_iterator<char>(g)),
		                        std::istreambuf_iterator<char>());
		std::ofstream f(path, std::ios::app | std::ios::binary);
		f.write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
	}
	return path;
}

int number(const mrpt::obs::CObservation::Ptr& o)
{
	const double t = mrpt::Clock::toDouble(o->timestamp);
	return static_cast<int>(std::lround((t - 1000.0) / 0.01));
}
}  // namespace
TEST(ReadAhead, ReadsFilesOneAfterTheOtherInOrder)
{
	const std::string d = tmpDir("order");
	const auto a = imuRawlog(d + "/a.rawlog", 0, 30);
	const auto b = imuRawlog(d + "/b.rawlog", 30, 25);
	for (bool threaded : {false, true})
	{
		ReadAhead in({a, b}, 4, threaded);
		int n = 0;
		for (;;)
		{
			const auto it = in.next();
			if (!it.obs) break;
			EXPECT_EQ(number(it.obs), n);
			EXPECT_EQ(it.file, n < 30 ? 0u : 1u);
			EXPECT_GE(it.readMs, 0.0);
			n++;
		}
		EXPECT_EQ(n, 55);
		EXPECT_FALSE(in.next().obs);  // the end, again
		EXPECT_EQ(in.path(1), b);
	}
}

TEST(ReadAhead, EachItemSaysWhichShareOfAllTheInputsIsRead)
{
	// for the progress line's estimated total (bims-run without --frames)
	const std::string d = tmpDir("fraction");
	const auto a = imuRawlog(d + "/a.rawlog", 0, 30);
	const auto b = imuRawlog(d + "/b.rawlog", 30, 30);
	ReadAhead in({a, b}, 4, true);
	double last = 0;
	int n = 0;
	for (;;)
	{
		const auto it = in.next();
		if (!it.obs) break;
		EXPECT_GT(it.inputFraction, last) << n;
		last = it.inputFraction;
		if (n == 29)
		{
			EXPECT_NEAR(it.inputFraction, 0.5, 1e-9);  // the end of a
		}
		n++;
	}
	EXPECT_EQ(n, 60);
	EXPECT_DOUBLE_EQ(last, 1.0);
}

TEST(ReadAhead, ATruncatedFileIsAnErrorAfterEverythingReadBeforeIt)
{
	const std::string d = tmpDir("truncated");
	const auto a = imuRawlog(d + "/a.rawlog", 0, 10);
	const auto cut = imuRawlog(d + "/cut.rawlog", 10, 7, true);
	const auto c = imuRawlog(d + "/c.rawlog", 17, 5);
	for (bool threaded : {false, true})
	{
		ReadAhead in({a, cut, c}, 3, threaded);
		int n = 0;
		std::string err;
		try
		{
			while (in.next().obs) n++;
		}
		catch (const bims::RawlogError& e)
		{
			err = e.what();
		}
		EXPECT_EQ(n, 17) << "threaded " << threaded;
		EXPECT_NE(err.find("cut.rawlog: truncated or corrupt"),
		          std::string::npos)
		    << err;
		EXPECT_THROW(in.next(), bims::RawlogError);  // again
	}
}

TEST(ReadAhead, AMissingFileIsAnErrorNamingIt)
{
	const std::string d = tmpDir("missing");
	const auto a = imuRawlog(d + "/a.rawlog", 0, 3);
	for (bool threaded : {false, true})
	{
		ReadAhead in({a, d + "/nope.rawlog"}, 2, threaded);
		for (int i = 0; i < 3; i++) EXPECT_TRUE(in.next().obs);
		try
		{
			in.next();
			ADD_FAILURE() << "no error";
		}
		catch (const bims::RawlogError& e)
		{
			EXPECT_NE(std::string(e.what()).find("nope.rawlog: no such rawlog"),
			          std::string::npos)
			    << e.what();
		}
	}
}

TEST(ReadAhead, StopsWhenDestroyedBeforeTheEnd)
{
	// The reading thread waits on a full queue; destroying the reader must
	// stop it (this test would hang otherwise).
	const std::string d = tmpDir("early");
	const auto a = imuRawlog(d + "/a.rawlog", 0, 200);
	for (int k = 0; k < 20; k++)
	{
		ReadAhead in({a}, 2, true);
		EXPECT_EQ(number(in.next().obs), 0);
	}
}
