#include <bims/io/trajectory.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <bims_test/tmp_dir.h>

using bims::test::tmpPath;

TEST(Trajectory, TumRoundTrip)
{
	bims::Trajectory t;
	for (int i = 0; i < 5; i++)
		t.push_back(
		    {1000.0 + i / 30.0, mrpt::poses::CPose3D(0.1 * i, -0.2 * i, 1.5,
		                                             0.3 * i, -0.1, 0.05 * i)});
	const auto p = tmpPath("bims_test_io", "traj.txt");
	bims::saveTumTrajectory(p, t, "test");
	const auto r = bims::loadTumTrajectory(p);
	ASSERT_EQ(r.size(), t.size());
	for (size_t i = 0; i < t.size(); i++)
	{
		EXPECT_NEAR(r[i].t, t[i].t, 1e-6);
		const auto d = (r[i].T_WC - t[i].T_WC);
		EXPECT_LT(d.translation().norm(), 1e-8);
		EXPECT_LT(std::abs(d.yaw()) + std::abs(d.pitch()) + std::abs(d.roll()),
		          1e-8);
	}
}

TEST(Trajectory, MalformedLinesAreErrorsWithLineNumbers)
{
	const auto p = tmpPath("bims_test_io", "bad_traj.txt");
	{
		std::ofstream f(p);
		f << "# comment\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0\n";
	}
	try
	{
		bims::loadTumTrajectory(p);
		FAIL();
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("bad_traj.txt:3:"),
		          std::string::npos)
		    << e.what();
	}
	{
		std::ofstream f(p);
		f << "1 0 0 0 0 0 0 2\n";
	}
	EXPECT_THROW(bims::loadTumTrajectory(p), std::runtime_error);
}

TEST(Trajectory, ANonFinitePoseIsAnErrorNamingItsTimeAndNothingIsWritten)
{
	const auto p = tmpPath("bims_test_io", "nan_traj.txt");
	std::remove(p.c_str());
	bims::Trajectory t;
	t.push_back({1.0, mrpt::poses::CPose3D(1, 2, 3, 0, 0, 0)});
	t.push_back({1.5, mrpt::poses::CPose3D(std::nan(""), 2, 3, 0, 0, 0)});
	try
	{
		bims::saveTumTrajectory(p, t);
		FAIL() << "no error";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find(p + ": the pose at t 1.5"),
		          std::string::npos)
		    << e.what();
	}
	EXPECT_FALSE(std::filesystem::exists(p));
}
