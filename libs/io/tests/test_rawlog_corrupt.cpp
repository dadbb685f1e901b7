// Corrupt rawlogs: declared sizes MRPT would trust, and a byte-flip campaign
// over the bundled sample; every case must end in RawlogError or a clean
// end, never a crash or a huge allocation.
#include <bims/io/rawlog.h>
#include <gtest/gtest.h>

#include <bims_test/tmp_dir.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/rtti/CObject.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

namespace
{
using bims::test::tmpPath;

std::vector<uint8_t> readBytes(const std::string& path)
{
	std::ifstream f(path, std::ios::binary);
	return {std::istreambuf_iterator<char>(f), {}};
}

void writeBytes(const std::string& path, const std::vector<uint8_t>& b)
{
	std::ofstream f(path, std::ios::binary | std::ios::trunc);
	f.write(reinterpret_cast<const char*>(b.data()),
	        static_cast<std::streamsize>(b.size()));
}

/** Byte offset of the first uint32 pair (a, b) in \a bytes. */
size_t findPair(const std::vector<uint8_t>& bytes, uint32_t a, uint32_t b)
{
	for (size_t i = 0; i + 8 <= bytes.size(); i++)
	{
		uint32_t x, y;
		std::memcpy(&x, &bytes[i], 4);
		std::memcpy(&y, &bytes[i + 4], 4);
		if (x == a && y == b) return i;
	}
	ADD_FAILURE() << "pair " << a << ", " << b << " not found";
	return 0;
}

/** A plain rawlog of one 3D scan of a 37 x 53 depth image (rows x columns:
 * sizes that occur nowhere else in the bytes), with \a points stored 3D
 * points when > 0 and, with \a labels, an RGB image and a 41 x 59
 * pixel-label image. */
std::vector<uint8_t> scanRawlog(const std::string& path, uint32_t points,
                                bool labels = false)
{
	mrpt::obs::CObservation3DRangeScan s;
	s.sensorLabel = "RGBD";
	s.hasRangeImage = true;
	s.rangeImage_setSize(37, 53);
	s.rangeImage.fill(1000);
	s.cameraParams.ncols = 53;
	s.cameraParams.nrows = 37;
	if (labels)
	{
		s.hasIntensityImage = true;
		s.intensityImage.resize(53, 37, mrpt::img::CH_RGB);
		auto l = std::make_shared<mrpt::obs::TPixelLabelInfo<1>>();
		l->setSize(41, 59);
		l->setLabelName(0, "walker");
		l->setLabelName(3, "door");
		s.pixelLabels = l;
	}
	if (points > 0)
	{
		s.hasPoints3D = true;
		s.resizePoints3DVectors(points);
	}
	{
		bims::RawlogWriter w(path, 0);
		w.write(s);
	}
	return readBytes(path);
}

/** The RawlogError text of reading \a path to its end ("" if none). */
std::string readError(const std::string& path)
{
	try
	{
		bims::RawlogReader r(path);
		while (r.next())
		{
		}
	}
	catch (const bims::RawlogError& e)
	{
		return e.what();
	}
	return {};
}

/** A plain rawlog of one default IMU observation; its bytes. */
std::vector<uint8_t> imuRawlog(const std::string& path)
{
	{
		mrpt::obs::CObservationIMU imu;
		bims::RawlogWriter w(path, 0);
		w.write(imu);
	}
	return readBytes(path);
}

void putU32(std::vector<uint8_t>& b, size_t at, uint32_t v)
{
	std::memcpy(&b[at], &v, 4);
}
}  // namespace

TEST(RawlogCorrupt, ASaneScanReadsBack)
{
	const auto p = tmpPath("bims_test_io", "scan_ok.rawlog");
	scanRawlog(p, 5);
	bims::RawlogReader r(p);
	auto s =
	    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(r.next());
	ASSERT_TRUE(s);
	EXPECT_EQ(s->rangeImage.rows(), 37);
	EXPECT_EQ(s->rangeImage.cols(), 53);
	EXPECT_EQ(s->points3D_x.size(), 5u);
	EXPECT_FALSE(r.next());
}

TEST(RawlogCorrupt, AHugeDepthImageSizeIsAnErrorNotAnAllocation)
{
	// MRPT 2.5.8 alone: a 1.3 TB allocation that fails silently, then a
	// segmentation fault (rows 0x7fffffff), or a 270 M pixel allocation.
	const auto p = tmpPath("bims_test_io", "scan_huge.rawlog");
	const auto good = scanRawlog(p, 0);
	const size_t at = findPair(good, 37, 53);
	const std::vector<std::pair<uint32_t, uint32_t>> sizes = {
	    {0x7fffffffu, 53}, {37, 0x7fffffffu}, {0xffffffffu, 53},
	    {16384, 16384},    {16385, 1},        {1, 16385}};
	for (const auto& [rows, cols] : sizes)
	{
		auto b = good;
		putU32(b, at, rows);
		putU32(b, at + 4, cols);
		writeBytes(p, b);
		const auto msg = readError(p);
		const auto want =
		    "scan_huge.rawlog: corrupt rawlog at entry 0 (0 "
		    "observations read before): the 3D scan's depth "
		    "image is " +
		    std::to_string(rows) + " x " + std::to_string(cols);
		EXPECT_NE(msg.find(want), std::string::npos) << msg;
	}
}

TEST(RawlogCorrupt, AHugeStoredPointCountIsAnError)
{
	const auto p = tmpPath("bims_test_io", "scan_points.rawlog");
	auto b = scanRawlog(p, 7);
	// the count precedes the points; 7 as uint32 followed by x of point 0
	// (0.0f) is the first such pair after the class name
	const size_t at = findPair(b, 7, 0);
	putU32(b, at, 0xfffffff0u);
	writeBytes(p, b);
	const auto msg = readError(p);
	EXPECT_NE(msg.find("the 3D scan declares 4294967280 stored points"),
	          std::string::npos)
	    << msg;
}

TEST(RawlogCorrupt, AHugePixelLabelImageIsAnError)
{
	// the labels follow the RGB image, both camera models and the strings:
	// the check walks every field of the scan up to them
	const auto p = tmpPath("bims_test_io", "scan_labels.rawlog");
	auto b = scanRawlog(p, 0, true);
	EXPECT_EQ(readError(p), "");
	const size_t at = findPair(b, 41, 59);
	putU32(b, at + 4, 0xffffff00u);
	writeBytes(p, b);
	const auto msg = readError(p);
	EXPECT_NE(msg.find("the 3D scan's pixel-label image is 41 x 4294967040"),
	          std::string::npos)
	    << msg;
}

/** Byte offset of the first occurrence of \a text in \a bytes. */
size_t findText(const std::vector<uint8_t>& bytes, const std::string& text)
{
	const auto it =
	    std::search(bytes.begin(), bytes.end(), text.begin(), text.end());
	EXPECT_NE(it, bytes.end()) << "'" << text << "' not found";
	return static_cast<size_t>(it - bytes.begin());
}

// MRPT's label reader allocates the label image with `new` and leaks it
// when anything after it throws (up to 15 MB per frame on corrupt files,
// seen under LeakSanitizer): each part after it is checked first.
TEST(RawlogCorrupt, CorruptPixelLabelNamesAreErrorsBeforeMrptReadsThem)
{
	const auto p = tmpPath("bims_test_io", "scan_label_names.rawlog");
	const auto clean = scanRawlog(p, 0, true);
	{
		bims::RawlogReader r(p);  // names read back: the walk knows them
		const auto o = r.next();
		const auto s =
		    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(o);
		ASSERT_TRUE(s && s->pixelLabels);
		EXPECT_EQ(s->pixelLabels->getLabelName(3), "door");
	}
	auto b = clean;  // the map's type names
	b[findText(b, "std::map")] = 'S';
	writeBytes(p, b);
	auto msg = readError(p);
	EXPECT_NE(msg.find("the pixel-label names' type 'std::map' expected"),
	          std::string::npos)
	    << msg;
	b = clean;  // the bytes per pixel (1 here): 9 is none of MRPT's (1-8)
	b[findPair(b, 41, 59) - 1] = 9;
	writeBytes(p, b);
	msg = readError(p);
	EXPECT_NE(msg.find("pixel labels declare 9 bytes per pixel, not 1 to 8"),
	          std::string::npos)
	    << msg;
	b = clean;  // more names than the bytes hold
	putU32(b, findText(b, "std::string") + 11, 1000);
	writeBytes(p, b);
	msg = readError(p);
	EXPECT_NE(msg.find("pixel-label names (1000 declared) run past the end"),
	          std::string::npos)
	    << msg;
}

TEST(RawlogCorrupt, SizesAtTheLimitAreLeftToMrpt)
{
	// 4096 x 16384 is 2^26 pixels, allowed: the file then ends inside the
	// image, which MRPT reports as a truncation.
	const auto p = tmpPath("bims_test_io", "scan_limit.rawlog");
	auto b = scanRawlog(p, 0);
	const size_t at = findPair(b, 37, 53);
	putU32(b, at, 4096);
	putU32(b, at + 4, 16384);
	writeBytes(p, b);
	const auto msg = readError(p);
	EXPECT_NE(msg.find("truncated or corrupt rawlog at entry 0"),
	          std::string::npos)
	    << msg;
}

TEST(RawlogCorrupt, ByteFlipsOfTheSampleNeverCrash)
{
	// The first 3 depth frames of the bundled sample (with the IMU samples
	// between them), rewritten plain; then 300 mutations at a fixed seed:
	// one byte set, one uint32 set to a size-like value, one bit flipped, or
	// a size field (a uint32 of the first scan equal to its image width or
	// height: depth, camera models, pixel labels) set to a huge value; most
	// of the others in the first scan's header.
	const auto base = tmpPath("bims_test_io", "sample_head.rawlog");
	size_t scans = 0, objects = 0;
	uint32_t rows = 0, cols = 0;
	{
		bims::RawlogReader r(std::string(BIMS_SOURCE_DIR) +
		                     "/rawlogs/pendulum_slow.rawlog");
		bims::RawlogWriter w(base, 0);
		while (auto o = r.next())
		{
			if (IS_CLASS(*o, mrpt::obs::CObservation3DRangeScan) && ++scans > 3)
				break;
			w.write(*o);
			objects++;
		}
	}
	const auto good = readBytes(base);
	const char kName[] = "mrpt::obs::CObservation3DRangeScan";
	const auto it =
	    std::search(good.begin(), good.end(), kName, kName + sizeof(kName) - 1);
	ASSERT_NE(it, good.end());
	const size_t scan0 = static_cast<size_t>(it - good.begin());

	std::vector<size_t> sizeLike;
	const auto scan1 =
	    std::search(it + 1, good.end(), kName, kName + sizeof(kName) - 1);
	for (size_t i = scan0; i + 4 <= static_cast<size_t>(scan1 - good.begin());
	     i++)
	{
		uint32_t v;
		std::memcpy(&v, &good[i], 4);
		if (v == rows || v == cols) sizeLike.push_back(i);
	}
	// depth image, two camera models and the pixel labels: 2 each at least
	ASSERT_GE(sizeLike.size(), 8u);

	std::mt19937 rng(1);
	const auto uniform = [&rng](size_t n)
	{ return std::uniform_int_distribution<size_t>(0, n - 1)(rng); };
	const uint32_t values[] = {0,           1,     0x7fffffffu, 0x80000000u,
	                           0xffffffffu, 65536, 100000};
	const auto p = tmpPath("bims_test_io", "sample_mutated.rawlog");
	size_t errors = 0, clean = 0;
	for (int k = 0; k < 300; k++)
	{
		auto b = good;
		const size_t at =
		    uniform(3) == 0 ? uniform(b.size() - 4) : scan0 + uniform(2000);
		switch (uniform(4))
		{
			case 3:
				putU32(b, sizeLike[uniform(sizeLike.size())],
				       uniform(2) ? 0x7fffffffu : 0x10000u + uniform(1u << 20));
				break;
			case 0:
				b[at] = static_cast<uint8_t>(uniform(256));
				break;
			case 1:
				putU32(b, at, values[uniform(std::size(values))]);
				break;
			default:
				b[at] ^= static_cast<uint8_t>(1u << uniform(8));
		}
		writeBytes(p, b);
		size_t n = 0;
		try
		{
			bims::RawlogReader r(p);
			while (r.next()) n++;
			clean++;
			EXPECT_LE(n, objects) << "mutation " << k;
		}
		catch (const bims::RawlogError& e)
		{
			errors++;
			EXPECT_NE(std::string(e.what()).find("sample_mutated.rawlog: "),
			          std::string::npos)
			    << e.what();
		}
	}
	EXPECT_EQ(errors + clean, 300u);
	EXPECT_GT(errors, 0u);  // the campaign does reach the checks
}

TEST(RawlogCorrupt, HugeStringLengthsAreErrorsNotAllocations)
{
	// Found by the rawlog fuzz target (tests/fuzz/corpus/rawlog/
	// oom-imu-label-length): an IMU observation whose sensor label declares
	// 0xffffffff bytes made MRPT allocate 4 GB before failing. Likewise a
	// 3D scan's label. The label "LBL1" is found by its bytes.
	const auto p = tmpPath("bims_test_io", "imu_label.rawlog");
	{
		mrpt::obs::CObservationIMU imu;
		imu.sensorLabel = "LBL1";
		mrpt::obs::CObservation3DRangeScan s;
		s.sensorLabel = "LBL2";
		s.hasRangeImage = true;
		s.rangeImage_setSize(4, 5);
		s.cameraParams.ncols = 5;
		s.cameraParams.nrows = 4;
		bims::RawlogWriter w(p, 0);
		w.write(imu);
		w.write(s);
	}
	const auto bytes = readBytes(p);
	EXPECT_EQ(readError(p), "");
	for (const char* label : {"LBL1", "LBL2"})
	{
		const auto at =
		    std::search(bytes.begin(), bytes.end(), label, label + 4) -
		    bytes.begin();
		ASSERT_GE(at, 4);
		auto bad = bytes;
		putU32(bad, static_cast<size_t>(at) - 4, 0xffffffffu);
		writeBytes(p, bad);
		const std::string err = readError(p);
		EXPECT_NE(err.find("sensor label declares 4294967295 bytes"),
		          std::string::npos)
		    << label << ": " << err;
	}
}

TEST(RawlogCorrupt, AnImuFlagThatIsNoBoolIsAnError)
{
	// Found by the rawlog fuzz target (tests/fuzz/corpus/rawlog/
	// ub-imu-flag-not-bool): a data-present flag stored as 10 is read into
	// a bool by MRPT, undefined behaviour in its accessors.
	const auto p = tmpPath("bims_test_io", "imu_flag.rawlog");
	auto bytes = imuRawlog(p);
	EXPECT_EQ(readError(p), "");
	// the flags follow the sensor pose's end byte 0x88 (its 12 doubles of a
	// default pose hold no 0x88)
	const auto pose =
	    std::search(bytes.begin(), bytes.end(), "CPose3D", "CPose3D" + 7);
	const auto end = std::find(pose, bytes.end(), 0x88);
	ASSERT_NE(end, bytes.end());
	*(end + 1 + 5) = 10;
	writeBytes(p, bytes);
	EXPECT_NE(readError(p).find("data-present flag 5 is 10"), std::string::npos)
	    << readError(p);
}

TEST(RawlogCorrupt, AnInnerObjectOfAnotherClassIsAnError)
{
	// Found by the rawlog fuzz target (tests/fuzz/corpus/rawlog/
	// oom-imu-pose-class-name): an IMU observation whose sensor pose is
	// named "mrpt::posei::CPose3D"; MRPT read on and allocated 4 GB.
	const auto p = tmpPath("bims_test_io", "imu_pose_class.rawlog");
	auto bytes = imuRawlog(p);
	const char* name = "mrpt::poses::";
	auto at = std::search(bytes.begin(), bytes.end(), name, name + 13);
	ASSERT_NE(at, bytes.end());
	*(at + 10) = 'i';  // poses -> posei
	writeBytes(p, bytes);
	EXPECT_NE(readError(p).find("the IMU observation does not hold MRPT's "
	                            "layout (a CPose3D expected at byte 28"),
	          std::string::npos)
	    << readError(p);
}

TEST(RawlogCorrupt, AnObjectOfAnUnknownClassIsAnError)
{
	// Found by the rawlog fuzz target (tests/fuzz/corpus/rawlog/
	// oom-unknown-class-name): a top-level object named
	// "mbpt::obs::CObservationIMU"; MRPT read on and allocated 4 GB.
	const auto p = tmpPath("bims_test_io", "unknown_class.rawlog");
	auto bytes = imuRawlog(p);
	EXPECT_TRUE(mrpt::rtti::findRegisteredClass("CObservationIMU", true))
	    << "a name without namespace is looked up as MRPT does";
	ASSERT_EQ(bytes[2], 'r');
	bytes[2] = 'b';  // mrpt -> mbpt
	writeBytes(p, bytes);
	EXPECT_NE(readError(p).find("corrupt rawlog at entry 0 (0 observations "
	                            "read before): an object of a class MRPT "
	                            "does not know ('mbpt::obs::CObservationIMU')"),
	          std::string::npos)
	    << readError(p);
}

TEST(RawlogCorrupt,
     ABlockRunningPastTheEndOfTheFileIsFoundBeforeMrptAllocatesIt)
{
	// a scan cut inside its depth image: the guard sees the image's bytes
	// end with the file and says so (MRPT would allocate the whole image
	// first, whatever size the bytes declare)
	const auto p = tmpPath("bims_test_io", "cut_depth.rawlog");
	auto bytes = scanRawlog(p, 0);
	const size_t at = findPair(bytes, 37, 53);  // the depth image's size
	bytes.resize(at + 8 + 100);
	writeBytes(p, bytes);
	EXPECT_NE(readError(p).find(
	              "truncated or corrupt rawlog at entry 0 (0 observations read "
	              "before): the 3D scan's depth image (3922 bytes) runs past "
	              "the end of the file"),
	          std::string::npos)
	    << readError(p);
}

TEST(RawlogCorrupt, AScanFlagThatIsNoBoolIsAnError)
{
	// Found by the rawlog fuzz target (tests/fuzz/corpus/rawlog/
	// ub-scan-flag-not-bool): a scan's flag stored as 121, read by MRPT into
	// a bool, undefined behaviour where bims reads it. Here range_is_depth:
	// after the label "RGBD" and two (flag, empty file name) pairs.
	const auto p = tmpPath("bims_test_io", "scan_flag.rawlog");
	auto bytes = scanRawlog(p, 0);
	const char* label = "RGBD";
	const auto at = std::search(bytes.begin(), bytes.end(), label, label + 4) -
	                bytes.begin();
	ASSERT_LT(static_cast<size_t>(at) + 14, bytes.size());
	ASSERT_EQ(bytes[static_cast<size_t>(at) + 14], 1);  // range_is_depth
	bytes[static_cast<size_t>(at) + 14] = 121;
	writeBytes(p, bytes);
	EXPECT_NE(readError(p).find(
	              "the 3D scan's range-is-depth flag is 121, not 0 or 1"),
	          std::string::npos)
	    << readError(p);
}

TEST(RawlogCorrupt, AJpegImageWhoseBytesDoNotDecodeIsAnErrorNotAnExit)
{
	// Found by the rawlog fuzz target (tests/fuzz/corpus/rawlog/
	// exit-jpeg-not-decodable, there through an image of an older version
	// inside a scan of version 10, now refused): MRPT decodes a JPEG-stored
	// image with libjpeg's default error handler, which ends the whole
	// process ("Not a JPEG file") instead of throwing.
	const auto p = tmpPath("bims_test_io", "jpeg.rawlog");
	const bool was = mrpt::img::CImage::DISABLE_JPEG_COMPRESSION();
	mrpt::img::CImage::DISABLE_JPEG_COMPRESSION(false);
	scanRawlog(p, 0, true);  // its RGB image stored as JPEG
	mrpt::img::CImage::DISABLE_JPEG_COMPRESSION(was);
	auto bytes = readBytes(p);
	EXPECT_EQ(readError(p), "");
	const uint8_t soi[3] = {0xff, 0xd8, 0xff};
	const auto at = std::search(bytes.begin(), bytes.end(), soi, soi + 3);
	ASSERT_NE(at, bytes.end()) << "no JPEG in the scan";
	std::fill(at, at + 3, 0);
	writeBytes(p, bytes);
	EXPECT_NE(readError(p).find("the 3D scan's intensity image is stored as "
	                            "JPEG but its bytes do not decode"),
	          std::string::npos)
	    << readError(p);
}

TEST(RawlogCorrupt, AJpegDeclaringAHugeImageIsAnErrorNotAnAllocation)
{
	// OpenCV (the guard's decode check) and MRPT allocate the whole image a
	// JPEG's frame header declares before decoding its few bytes: 30000 x
	// 30000 (under OpenCV's own limit of 2^30 pixels) is 2.7 GB
	const auto p = tmpPath("bims_test_io", "jpeg_size.rawlog");
	const bool was = mrpt::img::CImage::DISABLE_JPEG_COMPRESSION();
	mrpt::img::CImage::DISABLE_JPEG_COMPRESSION(false);
	scanRawlog(p, 0, true);  // its RGB image stored as JPEG
	mrpt::img::CImage::DISABLE_JPEG_COMPRESSION(was);
	auto bytes = readBytes(p);
	const uint8_t sof0[2] = {0xff, 0xc0};
	const auto at = std::search(bytes.begin(), bytes.end(), sof0, sof0 + 2);
	ASSERT_NE(at, bytes.end()) << "no JPEG frame header in the scan";
	ASSERT_EQ(*(at + 5), 0);  // height 37 (the image is 53 x 37)
	ASSERT_EQ(*(at + 6), 37);
	for (int k : {5, 7})  // height, width
	{
		*(at + k) = 30000 >> 8;
		*(at + k + 1) = 30000 & 0xff;
	}
	writeBytes(p, bytes);
	EXPECT_NE(
	    readError(p).find("the 3D scan's intensity image is 30000 x 30000"),
	    std::string::npos)
	    << readError(p);
}

TEST(RawlogCorrupt, AnImageOfAnotherFormatStoredAsJpegIsAnErrorNotAnExit)
{
	// the guard's decode check (OpenCV) decodes any format it knows, MRPT
	// only JPEG, with libjpeg's handler that ends the process on other
	// bytes: a valid PGM where the JPEG was must be refused (OpenCV would
	// also allocate whatever size a PPM or BMP header declares)
	const auto p = tmpPath("bims_test_io", "jpeg_pgm.rawlog");
	const bool was = mrpt::img::CImage::DISABLE_JPEG_COMPRESSION();
	mrpt::img::CImage::DISABLE_JPEG_COMPRESSION(false);
	auto bytes = scanRawlog(p, 0, true);
	mrpt::img::CImage::DISABLE_JPEG_COMPRESSION(was);
	const uint8_t soi[3] = {0xff, 0xd8, 0xff};
	const auto at = static_cast<size_t>(
	    std::search(bytes.begin(), bytes.end(), soi, soi + 3) - bytes.begin());
	ASSERT_LT(at, bytes.size());
	uint32_t n;
	std::memcpy(&n, &bytes[at - 4], 4);
	const std::string pgm = "P5\n2 2\n255\n\x01\x02\x03\x04";
	bytes.erase(bytes.begin() + static_cast<long>(at),
	            bytes.begin() + static_cast<long>(at + n));
	bytes.insert(bytes.begin() + static_cast<long>(at), pgm.begin(), pgm.end());
	putU32(bytes, at - 4, static_cast<uint32_t>(pgm.size()));
	writeBytes(p, bytes);
	EXPECT_NE(readError(p).find("the 3D scan's intensity image is stored as "
	                            "JPEG but its bytes do not decode"),
	          std::string::npos)
	    << readError(p);
}

namespace
{
/** MRPT's archive layout written by hand, for objects of the serialization
 * versions MRPT 2.x reads but no longer writes (MRPT 1.x's). */
struct Archive
{
	std::vector<uint8_t> b;

	template <typename T>
	Archive& put(T v)
	{
		const auto* p = reinterpret_cast<const uint8_t*>(&v);
		b.insert(b.end(), p, p + sizeof(T));
		return *this;
	}
	Archive& bytes(const std::vector<uint8_t>& v)
	{
		b.insert(b.end(), v.begin(), v.end());
		return *this;
	}
	Archive& str(const std::string& s)
	{
		put(static_cast<uint32_t>(s.size()));
		b.insert(b.end(), s.begin(), s.end());
		return *this;
	}
	/** An object's header: its class name, then its version. */
	Archive& object(const std::string& cls, uint8_t version)
	{
		put(static_cast<uint8_t>(0x80 | cls.size()));
		b.insert(b.end(), cls.begin(), cls.end());
		return put(version);
	}
	Archive& end() { return put(uint8_t{0x88}); }
	/** A matrix object (version 0) of \a rows x \a cols elements of type
	 * T (float: CMatrixF, double: CMatrixD), row by row. */
	template <typename T>
	Archive& matrix(const std::string& cls, uint32_t rows, uint32_t cols,
	                const std::vector<double>& values)
	{
		object(cls, 0).put(rows).put(cols);
		for (double v : values) put(static_cast<T>(v));
		return end();
	}
};

/** A 3D scan of an old serialization version, as MRPT 1.x (class names
 * without namespaces) or MRPT 2.0 wrote it: 2 stored points, a 3 x 5 depth
 * image of 1.5 m, an 8 x 4 intensity image (grey, of 7s, unless the image
 * version stores colour only), camera models and poses of the versions
 * given; the declared sizes may differ from what is stored. */
struct OldScan
{
	uint8_t version = 8;
	uint8_t poseVersion = 2, cameraVersion = 2, imageVersion = 8;
	bool namespaces = false;
	uint8_t hasPoints = 1;     ///< the flag's byte (versions 1 on)
	uint32_t points = 2;       ///< declared; 2 are stored
	uint32_t depthRows = 3;    ///< declared; 3 are stored
	uint32_t imageWidth = 8;   ///< declared; 8 are stored
	uint32_t imageBytes = 32;  ///< declared (image versions 0, 2 on)
	uint32_t labelLength = 7;  ///< declared length of "OLDSCAN"
	bool pixelLabels = false;  ///< 2 x 2 labels (versions 7 on)

	std::string cls(const char* ns, const char* name) const
	{
		return namespaces ? std::string(ns) + "::" + name : name;
	}
	/** CMatrixF's name: MRPT 1.x called it CMatrix. */
	std::string matrixF() const
	{
		return namespaces ? "mrpt::math::CMatrixF" : "CMatrix";
	}
	void pose(Archive& a) const
	{
		const std::vector<double> m = {1, 0, 0, 0.1, 0, 1, 0, 0.2,
		                               0, 0, 1, 0.3, 0, 0, 0, 1};
		a.object(cls("mrpt::poses", "CPose3D"), poseVersion);
		if (poseVersion == 0)
			a.matrix<float>(matrixF(), 4, 4, m);
		else if (poseVersion == 1)
			a.matrix<double>(cls("mrpt::math", "CMatrixD"), 4, 4, m);
		else if (poseVersion == 2)  // x y z, quaternion w x y z
			for (double v : {0.1, 0.2, 0.3, 1.0, 0.0, 0.0, 0.0}) a.put(v);
		else
			for (double v : {0.1, 0.2, 0.3, 1., 0., 0., 0., 1., 0., 0., 0., 1.})
				a.put(v);
		a.end();
	}
	void camera(Archive& a) const
	{
		const uint8_t v = cameraVersion;
		a.object(cls("mrpt::img", "TCamera"), v);
		a.put(0.0);  // focal length
		for (int k = 0; k < (v >= 3 ? 8 : 5); k++) a.put(0.0);
		if (v < 4)
		{
			a.object(cls("mrpt::math", "CMatrixD"), 0).put(3u).put(3u);
			for (double e : {4.0, 0.0, 2.5, 0.0, 4.0, 1.5, 0.0, 0.0, 1.0})
				a.put(e);
			a.end();
		}
		else
			for (double e : {4.0, 4.0, 2.5, 1.5}) a.put(e);
		if (v == 0)
			a.matrix<double>(cls("mrpt::math", "CMatrixD"), 1, 5,
			                 {0, 0, 0, 0, 0});
		if (v >= 2) a.put(3u).put(5u);  // nrows, ncols
		if (v >= 5) a.str("cam");
		if (v >= 6) a.put(uint8_t{1});  // plumb_bob
		a.end();
	}
	void image(Archive& a) const
	{
		const uint8_t v = imageVersion;
		a.object(cls("mrpt::img", "CImage"), v);
		const std::vector<uint8_t> grey(32, 7);
		if (v == 0)
		{
			a.put(imageWidth).put(4u).put(1u).put(uint8_t{1}).put(imageBytes);
			a.bytes(grey);
		}
		else if (v == 1)
			a.str(jpeg());
		else if (v == 100)
			a.put(uint8_t{0});  // not stored externally: no image
		else
		{
			if (v >= 6) a.put(uint8_t{0});  // not stored externally
			a.put(uint8_t{0});              // grey
			a.put(imageWidth).put(4u).put(0u).put(imageBytes);
			if (v >= 9) a.put(0u);          // 8-bit
			if (v >= 5) a.put(uint8_t{0});  // not ZIP-compressed
			a.bytes(grey);
		}
		a.end();
	}
	static std::string jpeg()
	{
		mrpt::img::CImage img(8, 4, mrpt::img::CH_RGB);
		img.filledRectangle(0, 0, 7, 3, mrpt::img::TColor(7, 7, 7));
		mrpt::io::CMemoryStream m;
		img.saveToStreamAsJPEG(m);
		const auto* p = static_cast<const char*>(m.getRawBufferData());
		return {p, p + m.getTotalBytesCount()};
	}

	std::vector<uint8_t> bytes() const
	{
		Archive a;
		a.object(cls("mrpt::obs", "CObservation3DRangeScan"), version);
		a.put(5.0f);  // maxRange
		pose(a);
		if (version >= 1) a.put(hasPoints);
		a.put(points);
		for (float v : {1.f, 2.f, 3.f, 4.f, 5.f, 6.f}) a.put(v);  // x, y, z
		if (version == 0) a.put(uint8_t{1}).put(uint8_t{1});      // valid
		if (version >= 8)
			for (uint16_t v : {1, 2, 3, 4}) a.put(v);  // pixel columns, rows
		if (version >= 1)
		{
			a.put(uint8_t{1});                // has range
			if (version >= 9) a.put(0.001f);  // range units
			if (version < 9)
				a.object(matrixF(), 0).put(depthRows).put(5u);
			else
				a.put(depthRows).put(5u);
			for (int k = 0; k < 15; k++)
				version < 9 ? a.put(1.5f) : a.put(uint16_t{1500});
			if (version < 9) a.end();
			a.put(uint8_t{1});  // has intensity
			image(a);
			a.put(uint8_t{0});  // no confidence
			if (version >= 2) camera(a);
			if (version >= 4)
			{
				camera(a);
				pose(a);
			}
		}
		a.put(0.01f).put(uint64_t{0});  // stdError, timestamp
		a.put(labelLength);
		a.bytes({'O', 'L', 'D', 'S', 'C', 'A', 'N'});
		if (version >= 3) a.put(uint8_t{0}).str("").put(uint8_t{0}).str("");
		if (version >= 5) a.put(uint8_t{1});  // range is depth
		if (version >= 6) a.put(int8_t{0});   // intensity channel
		if (version >= 7)
		{
			a.put(static_cast<uint8_t>(pixelLabels));
			if (pixelLabels)
			{
				a.put(uint8_t{1}).put(uint8_t{1}).put(2u).put(2u);
				a.bytes({1, 0, 0, 1});
				a.str("std::map").str("uint32_t").str("std::string").put(1u);
				a.put(0u).str("person");
			}
		}
		return a.end().b;
	}
};

/** Per scan version, inner objects of versions that occur with it (each
 * CPose3D and TCamera version at least once, each CImage version MRPT 2.x
 * reads but 3, always ZIP-compressed, and 100). */
OldScan oldScan(uint8_t version)
{
	OldScan o;
	o.version = version;
	o.poseVersion = version % 4;
	o.cameraVersion = version % 7;
	const uint8_t images[] = {0, 0, 1, 2, 4, 5, 6, 7, 8, 9};  // none in 0
	o.imageVersion = images[version];
	o.pixelLabels = version >= 7;
	o.namespaces = version == 9;  // MRPT 2.0 wrote version 9
	return o;
}

std::string readOld(const std::string& name, const OldScan& o)
{
	const auto p = tmpPath("bims_test_io", name);
	writeBytes(p, o.bytes());
	return readError(p);
}
}  // namespace

TEST(RawlogCorrupt, ValidScansOfEveryOldLayoutAreRead)
{
	// MRPT 1.x recordings (scan versions 0-8) and MRPT 2.0's (9): the guard
	// walks them to their end flag and MRPT reads them as written
	for (uint8_t v = 0; v <= 9; v++)
	{
		// one file per version: the rawlog fuzz target's old-layout seeds
		// (tests/fuzz/corpus/rawlog/old-scan-v*) are some of them
		const auto p = tmpPath("bims_test_io",
		                       "old_scan_v" + std::to_string(v) + ".rawlog");
		writeBytes(p, oldScan(v).bytes());
		bims::RawlogReader r(p);
		mrpt::obs::CObservation::Ptr o;
		ASSERT_NO_THROW(o = r.next()) << "version " << int(v);
		const auto s =
		    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(o);
		ASSERT_TRUE(s) << "version " << int(v);
		EXPECT_EQ(s->sensorLabel, "OLDSCAN") << "version " << int(v);
		EXPECT_EQ(s->points3D_x.size(), 2u);
		EXPECT_FLOAT_EQ(s->points3D_z.at(1), 6.f);
		EXPECT_NEAR(s->sensorPose.x(), 0.1, 1e-6) << "version " << int(v);
		if (v >= 1)
		{
			EXPECT_EQ(s->rangeImage.rows(), 3) << "version " << int(v);
			EXPECT_EQ(s->rangeImage.cols(), 5);
			EXPECT_EQ(s->rangeImage(2, 4), 1500) << "version " << int(v);
			EXPECT_EQ(s->intensityImage.getWidth(), 8u) << "version " << int(v);
			EXPECT_EQ(s->intensityImage.getHeight(), 4u);
		}
		if (v >= 4)
		{
			EXPECT_DOUBLE_EQ(s->cameraParamsIntensity.cx(), 2.5);
		}
		if (v >= 7)
		{
			ASSERT_TRUE(s->pixelLabels) << "version " << int(v);
			EXPECT_EQ(s->pixelLabels->getLabelName(0), "person");
		}
		EXPECT_FALSE(r.next());
	}
	// an image of an MRPT without OpenCV (version 100): no pixels
	auto o = oldScan(8);
	o.imageVersion = 100;
	EXPECT_EQ(readOld("old_image_100.rawlog", o), "");
	// version 3 stored every grey image ZIP-compressed, which MRPT 2.x no
	// longer reads (it throws once it has allocated the pixels)
	o.imageVersion = 3;
	EXPECT_NE(readOld("old_image_zip.rawlog", o)
	              .find("the 3D scan's intensity image is stored "
	                    "ZIP-compressed, which MRPT 2.x no longer reads"),
	          std::string::npos);
}

TEST(RawlogCorrupt,
     AnOldLayoutScanWithAHugeDeclaredSizeIsAnErrorNotAnAllocation)
{
	// MRPT 2.5.8 reads the old layouts trusting every stored size: a scan
	// whose version byte was mutated to 0 made it allocate 2.7 GB. The
	// guard walks every version and names the size first.
	for (uint8_t v = 0; v <= 9; v++)
	{
		auto o = oldScan(v);
		o.points = 0x7fffffff;
		EXPECT_NE(readOld("old_points.rawlog", o)
		              .find("corrupt rawlog at entry 0 (0 observations read "
		                    "before): the 3D scan declares 2147483647 stored "
		                    "points"),
		          std::string::npos)
		    << "version " << int(v);
		o = oldScan(v);
		o.labelLength = 0xfffffff0u;
		EXPECT_NE(readOld("old_label.rawlog", o)
		              .find("the 3D scan's sensor label declares 4294967280 "
		                    "bytes"),
		          std::string::npos)
		    << "version " << int(v);
		if (v == 0) continue;  // no images yet
		o = oldScan(v);
		o.depthRows = 0x7fffffff;
		EXPECT_NE(readOld("old_depth.rawlog", o)
		              .find("the 3D scan's depth image is 2147483647 x 5"),
		          std::string::npos)
		    << "version " << int(v);
		o = oldScan(v);
		o.depthRows = 300;  // 1500 pixels declared, 15 stored
		EXPECT_NE(readOld("old_depth_cut.rawlog", o)
		              .find("truncated or corrupt rawlog at entry 0 (0 "
		                    "observations read before): the 3D scan's depth "
		                    "image (" +
		                    std::to_string(v < 9 ? 6000 : 3000) +
		                    " bytes) runs past the end of the file"),
		          std::string::npos)
		    << "version " << int(v);
		o = oldScan(v);
		o.imageWidth = 0x10000000;
		if (o.imageVersion == 1 || o.imageVersion == 100) continue;
		EXPECT_NE(readOld("old_image.rawlog", o)
		              .find("the 3D scan's intensity image is 4 x 268435456"),
		          std::string::npos)
		    << "version " << int(v);
	}
	auto o = oldScan(0);  // the pose of version 0: a CMatrixF
	ASSERT_EQ(o.poseVersion, 0);
	const auto clean = o.bytes();
	auto b = clean;
	putU32(b, findPair(b, 4, 4), 0x7ffffff0u);
	const auto p = tmpPath("bims_test_io", "old_pose.rawlog");
	writeBytes(p, b);
	EXPECT_NE(readError(p).find("the 3D scan's pose matrix is 2147483632 x 4"),
	          std::string::npos)
	    << readError(p);
}

TEST(RawlogCorrupt, AnOldLayoutScanFlagThatIsNoBoolIsAnError)
{
	for (uint8_t v = 1; v <= 9; v++)
	{
		auto o = oldScan(v);
		o.hasPoints = 7;
		EXPECT_NE(readOld("old_flag.rawlog", o)
		              .find("the 3D scan's has-points flag is 7, not 0 or 1"),
		          std::string::npos)
		    << "version " << int(v);
	}
}

TEST(RawlogCorrupt, AnOldImageDeclaringOtherBytesThanItsPixelsIsAnError)
{
	// CImage version 0 reads the declared byte count into the pixels it
	// allocated: more bytes than pixels would be written past them
	auto o = oldScan(1);
	ASSERT_EQ(o.imageVersion, 0);
	o.imageBytes = 1u << 20;
	EXPECT_NE(readOld("old_image_bytes.rawlog", o)
	              .find("the 3D scan's intensity image declares 1048576 "
	                    "bytes, not its 8 x 4 x 1 pixels' 32"),
	          std::string::npos);
	o.imageWidth = 16384;  // 64 KB allocated for the 32 bytes stored
	o.imageBytes = 32;
	EXPECT_NE(readOld("old_image_bytes.rawlog", o)
	              .find("declares 32 bytes, not its 16384 x 4 x 1 pixels' "
	                    "65536"),
	          std::string::npos);
	// versions 2 on: MRPT allocates the pixels, then requires the size to
	// match them
	o = oldScan(6);
	ASSERT_EQ(o.imageVersion, 6);
	o.imageBytes = 33;
	EXPECT_NE(readOld("old_image_bytes.rawlog", o)
	              .find("the 3D scan's intensity image declares 33 bytes for "
	                    "8 x 4 pixels of 1 bytes (32)"),
	          std::string::npos);
}

TEST(RawlogCorrupt, AScanCutInsideASizeFieldIsAnErrorNotAGarbageSize)
{
	// Found by the rawlog fuzz target (tests/fuzz/corpus/rawlog/
	// oom-point-count-cut): a scan of version 2 ending 2 bytes into its
	// point count. MRPT reads the 2 bytes, keeps the other 2 uninitialized
	// and allocated 9 GB for the count.
	auto o = oldScan(2);
	auto b = o.bytes();
	const auto p = tmpPath("bims_test_io", "cut_count.rawlog");
	const size_t at = findPair(b, 2, 0x3f800000u);  // count 2, x = 1.0f
	b.resize(at + 2);
	writeBytes(p, b);
	EXPECT_NE(readError(p).find("truncated or corrupt rawlog at entry 0 (0 "
	                            "observations read before): the 3D scan's "
	                            "layout runs past the end of the file (the "
	                            "entry holds " +
	                            std::to_string(at + 2) + " bytes)"),
	          std::string::npos)
	    << readError(p);
	// MRPT 2.x's layout alike: cut inside the depth image's row count
	auto v10 = scanRawlog(p, 0);
	v10.resize(findPair(v10, 37, 53) + 2);
	writeBytes(p, v10);
	EXPECT_NE(readError(p).find("the 3D scan's layout runs past the end of "
	                            "the file"),
	          std::string::npos)
	    << readError(p);
}

TEST(RawlogCorrupt, AnOldImuObservationWithAHugeVectorIsAnError)
{
	// IMU observations of versions 0-3 (MRPT 1.x) store their flags and
	// measurements as vectors, whose declared lengths MRPT allocates before
	// finding them longer than the 31 it keeps
	const auto imu = [](uint32_t flags, uint32_t values)
	{
		Archive a;
		a.object("CObservationIMU", 3).object("CPose3D", 2);
		for (int k = 0; k < 7; k++) a.put(k == 3 ? 1.0 : 0.0);
		a.end().put(flags);
		for (uint32_t k = 0; k < std::min(flags, 31u); k++) a.put(uint8_t{1});
		a.put(uint64_t{0}).put(values);
		for (uint32_t k = 0; k < std::min(values, 31u); k++) a.put(9.81);
		return a.str("IMU1").end().b;
	};
	const auto p = tmpPath("bims_test_io", "old_imu.rawlog");
	writeBytes(p, imu(21, 21));
	{
		bims::RawlogReader r(p);
		const auto o =
		    std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(r.next());
		ASSERT_TRUE(o);
		EXPECT_EQ(o->sensorLabel, "IMU1");
		EXPECT_TRUE(o->dataIsPresent[20]);
		EXPECT_DOUBLE_EQ(o->rawMeasurements[0], 9.81);
	}
	writeBytes(p, imu(0xffffffffu, 21));
	EXPECT_NE(readError(p).find("the IMU observation's data-present flags "
	                            "declare 4294967295 entries, beyond the 31"),
	          std::string::npos)
	    << readError(p);
	writeBytes(p, imu(21, 0x20000000u));
	EXPECT_NE(readError(p).find("the IMU observation's measurements declare "
	                            "536870912 entries"),
	          std::string::npos)
	    << readError(p);
}

TEST(RawlogCorrupt, ASensoryFrameDeclaringMoreObservationsThanBytesIsAnError)
{
	// Found by the rawlog fuzz target (tests/fuzz/corpus/rawlog/
	// oom-sensory-frame-count): a CSensorialFrame declaring 1 086 359 807
	// observations; MRPT sized its list (16 GB) before reading any.
	const auto p = tmpPath("bims_test_io", "sensory_frame.rawlog");
	{
		mrpt::obs::CSensoryFrame sf;
		auto imu = mrpt::obs::CObservationIMU::Create();
		imu->sensorLabel = "IMU";
		imu->set(mrpt::obs::IMU_WZ, 0.5);
		sf.insert(imu);
		mrpt::io::CFileOutputStream f(p);
		mrpt::serialization::archiveFrom(f) << sf;
	}
	{
		// a sane frame reads back, its observation walked and kept
		bims::RawlogReader r(p);
		auto imu =
		    std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(r.next());
		ASSERT_TRUE(imu);
		EXPECT_DOUBLE_EQ(imu->get(mrpt::obs::IMU_WZ), 0.5);
	}
	auto bytes = readBytes(p);
	const std::string name = "CSensoryFrame";
	const auto it =
	    std::search(bytes.begin(), bytes.end(), name.begin(), name.end());
	ASSERT_NE(it, bytes.end());
	const size_t count = static_cast<size_t>(it - bytes.begin()) + name.size() +
	                     1;  // after the version byte
	uint32_t n = 0;
	std::memcpy(&n, &bytes[count], 4);
	ASSERT_EQ(n, 1u);
	putU32(bytes, count, 0x40c088ffu);
	writeBytes(p, bytes);
	EXPECT_NE(readError(p).find("the sensory frame declares 1086359807 "
	                            "observations, more than the 1048576 a "
	                            "rawlog may hold"),
	          std::string::npos)
	    << readError(p);
	// fewer, but more than the file's bytes (oom-sensory-frame-count-2 held
	// 2 153 775 104: the guard's own peek of that many bytes ran out of
	// memory)
	putU32(bytes, count, 4096);
	writeBytes(p, bytes);
	EXPECT_NE(readError(p).find("the sensory frame declares 4096 "
	                            "observations, more than the bytes left in "
	                            "the file"),
	          std::string::npos)
	    << readError(p);
}

TEST(RawlogCorrupt, AnObjectThatIsNoRawlogEntryIsAnErrorBeforeMrptReadsIt)
{
	// Found by the rawlog fuzz target (tests/fuzz/corpus/rawlog/
	// oom-top-level-pose-matrix): a top-level CPose3D of version 1 whose
	// CMatrixD declared 22 GB; MRPT allocated them before the reader could
	// see the entry is no observation. A valid pose is refused as well, by
	// the guard, naming its class.
	const auto p = tmpPath("bims_test_io", "pose_entry.rawlog");
	{
		auto f = mrpt::io::CFileOutputStream(p);
		auto a = mrpt::serialization::archiveFrom(f);
		a << mrpt::poses::CPose3D(1, 2, 3, 0, 0, 0);
	}
	EXPECT_NE(readError(p).find("corrupt rawlog at entry 0 (0 observations "
	                            "read before): an object of class "
	                            "'mrpt::poses::CPose3D', not an observation, "
	                            "sensory frame or action collection"),
	          std::string::npos)
	    << readError(p);
	// an action collection stays a valid entry (skipped), before an IMU
	// observation that is read
	{
		auto f = mrpt::io::CFileOutputStream(p);
		auto a = mrpt::serialization::archiveFrom(f);
		a << mrpt::obs::CActionCollection() << mrpt::obs::CObservationIMU();
	}
	bims::RawlogReader r(p);
	const auto o = r.next();
	ASSERT_TRUE(o);
	EXPECT_TRUE(std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o));
	EXPECT_FALSE(r.next());
}
