// Gzip rawlogs written as independent members (bims/io/gzip_members.h):
// every reader sees one stream, the bytes do not depend on the threads'
// timing, a flushed file survives a kill, a full disk leaves whole members.
#include <bims/io/gzip_members.h>
#include <bims/io/rawlog.h>
#include <gtest/gtest.h>

#include <bims_test/file_size_limit.h>
#include <bims_test/incompressible_rawlog.h>
#include <bims_test/run_command.h>
#include <bims_test/tmp_dir.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/serialization/CArchive.h>
#include <opencv2/core.hpp>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace
{
using bims::test::tmpPath;
using mrpt::obs::CObservation3DRangeScan;
using mrpt::obs::CObservationIMU;

std::string fileBytes(const std::string& path)
{
	std::ifstream f(path, std::ios::binary);
	return {std::istreambuf_iterator<char>(f), {}};
}

/** \a n bytes that compress somewhat (a slowly changing random walk). */
std::vector<uint8_t> walkBytes(size_t n, uint32_t seed)
{
	std::vector<uint8_t> v(n);
	uint32_t x = seed;
	uint8_t b = 0;
	for (auto& c : v)
	{
		x = x * 1664525u + 1013904223u;
		if ((x >> 28) == 0) b = static_cast<uint8_t>(x >> 20);
		c = b;
	}
	return v;
}

/** A 640x480 scan with range and colour whose pixels depend on \a k. */
CObservation3DRangeScan::Ptr scan(int k)
{
	auto s = CObservation3DRangeScan::Create();
	s->sensorLabel = "RGBD";
	s->timestamp = mrpt::Clock::fromDouble(100.0 + k / 30.0);
	s->hasRangeImage = true;
	s->rangeImage_setSize(480, 640);
	const auto walk = walkBytes(640 * 480 * 4, 7 + k);
	for (int v = 0; v < 480; v++)
		for (int u = 0; u < 640; u++)
			s->rangeImage(v, u) =
			    static_cast<uint16_t>(500 + walk[v * 640 + u] * 8);
	s->hasIntensityImage = true;
	s->intensityImage.resize(640, 480, mrpt::img::CH_RGB);
	for (int v = 0; v < 480; v++)
		for (int u = 0; u < 640; u++)
			for (int c = 0; c < 3; c++)
				*s->intensityImage(u, v, c) =
				    walk[640 * 480 + (v * 640 + u) * 3 + c];
	return s;
}

void writeScans(const std::string& path, int n, int gz, int flushAt = -1)
{
	bims::RawlogWriter w(path, gz);
	for (int k = 0; k < n; k++)
	{
		w.write(*scan(k));
		if (k == flushAt) w.flush();
	}
	w.close();
}

void expectSameScan(const CObservation3DRangeScan& a,
                    const CObservation3DRangeScan& b)
{
	EXPECT_EQ(a.timestamp, b.timestamp);
	EXPECT_EQ(a.sensorLabel, b.sensorLabel);
	EXPECT_TRUE(a.rangeImage == b.rangeImage);
	ASSERT_EQ(a.intensityImage.getWidth(), b.intensityImage.getWidth());
	EXPECT_EQ(a.intensityImage.asCvMatRef().size(),
	          b.intensityImage.asCvMatRef().size());
	EXPECT_EQ(cv::norm(a.intensityImage.asCvMatRef(),
	                   b.intensityImage.asCvMatRef(), cv::NORM_INF),
	          0);
}

/** The number of gzip members of \a path (Python's zlib, member by
 * member), -1 if Python cannot read it. */
int membersOf(const std::string& path)
{
	const auto r = bims::test::runCommand(
	    "python3 -c \"import sys, zlib\n"
	    "data = open(sys.argv[1], 'rb').read()\n"
	    "n = 0\n"
	    "while data:\n"
	    "    d = zlib.decompressobj(31)\n"
	    "    d.decompress(data)\n"
	    "    assert d.eof\n"
	    "    data = d.unused_data\n"
	    "    n += 1\n"
	    "print(n)\" '" +
	    path + "'");
	return r.code == 0 ? std::stoi(r.out) : -1;
}
}  // namespace

TEST(GzipMembers, ZcatPythonAndMrptReadTheMembersAsOneStream)
{
	const auto raw = walkBytes(5'500'000, 3);
	const auto p = tmpPath("bims_test_io", "members.gz");
	const auto plain = tmpPath("bims_test_io", "members.bin");
	std::ofstream(plain, std::ios::binary)
	    .write(reinterpret_cast<const char*>(raw.data()), raw.size());
	{
		bims::GzipMemberWriter w(p, 1, 2, 1'000'000);
		for (size_t at = 0; at < raw.size(); at += 100'000)
			w.append(raw.data() + at,
			         std::min<size_t>(100'000, raw.size() - at));
		w.close();
	}
	EXPECT_EQ(membersOf(p), 6);
	auto r = bims::test::runCommand("zcat '" + p + "' | cmp - '" + plain + "'");
	EXPECT_EQ(r.code, 0) << r.out;
	r = bims::test::runCommand(
	    "python3 -c \"import gzip, sys\n"
	    "sys.exit(gzip.open(sys.argv[1]).read() != open(sys.argv[2], "
	    "'rb').read())\" '" +
	    p + "' '" + plain + "'");
	EXPECT_EQ(r.code, 0) << r.out;
	mrpt::io::CFileGZInputStream in(p);
	std::vector<uint8_t> back(raw.size() + 10);
	size_t got = 0;
	while (size_t k = in.Read(back.data() + got, back.size() - got)) got += k;
	back.resize(got);
	EXPECT_TRUE(back == raw);
	EXPECT_EQ(bims::gzipDataBytes(p), raw.size());
}

TEST(GzipMembers, AFileOfNoDataIsOneEmptyMember)
{
	const auto p = tmpPath("bims_test_io", "empty_members.rawlog");
	bims::RawlogWriter(p, 1).close();
	EXPECT_EQ(membersOf(p), 1);
	EXPECT_EQ(bims::gzipDataBytes(p), 0u);
	bims::RawlogReader r(p);
	EXPECT_FALSE(r.next());
}

TEST(Rawlog, AGzipRawlogOfSeveralMembersReadsBackEveryObservation)
{
	// 12 scans of ~1.5 MB: members of ~2 MB hold whole observations
	const int n = 12;
	const auto gz = tmpPath("bims_test_io", "scans_members.rawlog");
	const auto plain = tmpPath("bims_test_io", "scans_plain.rawlog");
	writeScans(gz, n, 1);
	writeScans(plain, n, 0);
	EXPECT_GT(membersOf(gz), 4);
	// the data is the plain rawlog's, byte for byte
	auto r =
	    bims::test::runCommand("zcat '" + gz + "' | cmp - '" + plain + "'");
	EXPECT_EQ(r.code, 0) << r.out;
	EXPECT_EQ(bims::rawlogDataBytes(gz), std::filesystem::file_size(plain));
	// bims's reader
	{
		bims::RawlogReader in(gz);
		int k = 0;
		while (auto o = in.next())
		{
			auto s = std::dynamic_pointer_cast<CObservation3DRangeScan>(o);
			ASSERT_TRUE(s);
			ASSERT_LT(k, n);
			expectSameScan(*s, *scan(k++));
			EXPECT_LE(in.bytesRead(), bims::rawlogDataBytes(gz));
		}
		EXPECT_EQ(k, n);
		EXPECT_EQ(in.bytesRead(), bims::rawlogDataBytes(gz));
	}
	// MRPT's own
	mrpt::io::CFileGZInputStream in(gz);
	auto arch = mrpt::serialization::archiveFrom(in);
	for (int k = 0; k < n; k++)
	{
		auto s = std::dynamic_pointer_cast<CObservation3DRangeScan>(
		    arch.ReadObject());
		ASSERT_TRUE(s) << k;
		expectSameScan(*s, *scan(k));
	}
	uint8_t more = 0;
	EXPECT_EQ(in.Read(&more, 1), 0u);
}

TEST(Rawlog, AGzipRawlogIsTheSameByteForByteEveryTime)
{
	// the members end by the data written and the flushes, never by the
	// workers' timing
	const auto a = tmpPath("bims_test_io", "det_a.rawlog");
	const auto b = tmpPath("bims_test_io", "det_b.rawlog");
	writeScans(a, 9, 1, 4);
	writeScans(b, 9, 1, 4);
	const std::string bytes = fileBytes(a);
	EXPECT_GT(bytes.size(), 1000u);
	EXPECT_TRUE(bytes == fileBytes(b));
	// a flush elsewhere ends a member elsewhere: the same data, other bytes
	writeScans(b, 9, 1, 2);
	EXPECT_FALSE(bytes == fileBytes(b));
	const auto r = bims::test::runCommand("bash -c \"cmp <(zcat '" + a +
	                                      "') <(zcat '" + b + "')\"");
	EXPECT_EQ(r.code, 0) << r.out;
}

TEST(Rawlog, AGzipRawlogFlushedThenKilledReadsBackToTheFlush)
{
	// the program killed after flush(): a whole gzip file up to there, the
	// observations written since in no member yet
	const auto p = tmpPath("bims_test_io", "killed.rawlog");
	const int code =
	    bims::test::exitOfChildWithFileSizeLimit(RLIM_INFINITY,
	                                             [&]
	                                             {
		                                             bims::RawlogWriter w(p, 1);
		                                             for (int k = 0; k < 3; k++)
			                                             w.write(*scan(k));
		                                             w.flush();
		                                             for (int k = 3; k < 5; k++)
			                                             w.write(*scan(k));
		                                             std::raise(SIGKILL);
		                                             return 0;
	                                             });
	EXPECT_EQ(code, -1);
	bims::RawlogReader r(p);
	int k = 0;
	while (auto o = r.next())
	{
		auto s = std::dynamic_pointer_cast<CObservation3DRangeScan>(o);
		ASSERT_TRUE(s);
		expectSameScan(*s, *scan(k++));
	}
	EXPECT_EQ(k, 3);
}

TEST(Rawlog, AFullDiskLeavesAGzipRawlogAtItsLastWholeMember)
{
	// observations of 300 kB that do not compress, in a child limited to
	// 3 MB files: the first member (7 of them, ~2.1 MB) is written, the
	// second fails; the error names the file and the file reads back whole
	const auto p = tmpPath("bims_test_io", "gz_full.rawlog");
	const int code = bims::test::writeIncompressibleOnAFullDisk(
	    p, 1, 3'000'000, 20, 300'000, p + ": write failed");
	EXPECT_EQ(code, 3);
	bims::RawlogReader r(p);
	int n = 0;
	while (auto o = r.next())
		EXPECT_EQ(mrpt::Clock::toDouble(o->timestamp), 10.0 + n++);
	EXPECT_EQ(n, 7);
	std::filesystem::remove(p);
}
