// BulkPixelLabels writes exactly the bytes of MRPT's TPixelLabelInfo<1>.
#include <bims/io/pixel_labels.h>
#include <bims/io/rawlog.h>
#include <gtest/gtest.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/serialization/CArchive.h>

#include <filesystem>
#include <random>

namespace
{
std::vector<uint8_t> bytesOf(const mrpt::obs::TPixelLabelInfoBase& l)
{
	mrpt::io::CMemoryStream buf;
	auto arch = mrpt::serialization::archiveFrom(buf);
	l.writeToStream(arch);
	const auto* d = static_cast<const uint8_t*>(buf.getRawBufferData());
	return std::vector<uint8_t>(d, d + buf.getTotalBytesCount());
}

// The same labels and names in both classes.
template <class A, class B>
void fill(A& a, B& b, int rows, int cols, int names, std::mt19937& rng)
{
	a.setSize(rows, cols);
	b.setSize(rows, cols);
	for (int i = 0; i < names; ++i)
	{
		const std::string n = "label " + std::to_string(i * 3);
		a.setLabelName(unsigned(i * 3 % 8), n);
		b.setLabelName(unsigned(i * 3 % 8), n);
	}
	for (int r = 0; r < rows; ++r)
		for (int c = 0; c < cols; ++c)
		{
			const uint8_t v = uint8_t(rng() % 5 == 0 ? rng() : 0);
			a.pixelLabels(r, c) = v;
			b.pixelLabels(r, c) = v;
		}
}
}  // namespace

TEST(PixelLabels, BulkWriteHasMrptsBytes)
{
	std::mt19937 rng(3);
	const int sizes[][2] = {{0, 0},   {1, 1},   {2, 3},     {33, 31},
	                        {31, 70}, {64, 64}, {480, 640}, {241, 319}};
	int n = 0;
	for (const auto& s : sizes)
		for (int names : {0, 1, 3})
		{
			mrpt::obs::TPixelLabelInfo<1> mrptLabels;
			bims::BulkPixelLabels bulk;
			fill(mrptLabels, bulk, s[0], s[1], names, rng);
			ASSERT_EQ(bytesOf(bulk), bytesOf(mrptLabels))
			    << s[0] << "x" << s[1] << ", " << names << " names";
			++n;
		}
	EXPECT_EQ(n, 24);
}

// Through a rawlog: a scan with bulk labels reads back (as MRPT's
// TPixelLabelInfo<1>) with the same labels and names.
TEST(PixelLabels, ScanWithBulkLabelsReadsBackFromARawlog)
{
	const auto dir =
	    std::filesystem::temp_directory_path() / "bims_test_common";
	std::filesystem::create_directories(dir);
	const std::string path = (dir / "bulk_labels.rawlog").string();
	std::mt19937 rng(5);
	auto labels = std::make_shared<bims::BulkPixelLabels>();
	mrpt::obs::TPixelLabelInfo<1> want;
	fill(want, *labels, 48, 64, 1, rng);
	{
		mrpt::obs::CObservation3DRangeScan scan;
		scan.sensorLabel = "depth";
		scan.hasRangeImage = true;
		scan.rangeImage_setSize(48, 64);
		scan.rangeImage.fill(1000);
		scan.pixelLabels = labels;
		bims::RawlogWriter w(path, 0);
		w.write(scan);
		w.close();
	}
	bims::RawlogReader r(path);
	auto obs = r.next();
	auto scan =
	    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(obs);
	ASSERT_TRUE(scan);
	ASSERT_TRUE(scan->hasPixelLabels());
	auto got = std::dynamic_pointer_cast<mrpt::obs::TPixelLabelInfo<1>>(
	    scan->pixelLabels);
	ASSERT_TRUE(got);
	EXPECT_EQ(got->pixelLabelNames, want.pixelLabelNames);
	ASSERT_EQ(got->pixelLabels.rows(), 48);
	ASSERT_EQ(got->pixelLabels.cols(), 64);
	for (int v = 0; v < 48; ++v)
		for (int u = 0; u < 64; ++u)
			ASSERT_EQ(got->pixelLabels(v, u), want.pixelLabels(v, u))
			    << v << " " << u;
	EXPECT_FALSE(r.next());
}
