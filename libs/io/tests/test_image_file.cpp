// The one guarded image reader: headers of PNG, JPEG, TIFF and BMP read
// for their size, a decompression bomb refused before decoding, and every
// other bad file a one-line error naming it.
#include <bims/io/image_file.h>
#include <bims_test/png_bomb.h>
#include <bims_test/tmp_dir.h>
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

namespace
{
std::string errorOf(const std::string& path, int flags = cv::IMREAD_UNCHANGED)
{
	try
	{
		bims::readImageFile(path, flags, "test image");
	}
	catch (const std::runtime_error& e)
	{
		return e.what();
	}
	return "";
}
}  // namespace

TEST(ImageFile, HeadersOfTheFourFormatsGiveTheirSize)
{
	const cv::Mat img(37, 53, CV_8UC3, cv::Scalar(10, 200, 30));
	for (const char* ext : {".png", ".jpg", ".tiff", ".bmp"})
	{
		std::vector<uint8_t> bytes;
		ASSERT_TRUE(cv::imencode(ext, img, bytes)) << ext;
		const auto h = bims::imageHeader(bytes.data(), bytes.size());
		ASSERT_TRUE(h.has_value()) << ext;
		EXPECT_EQ(h->width, 53u) << ext;
		EXPECT_EQ(h->height, 37u) << ext;
		// cut before the size: no header
		EXPECT_FALSE(bims::imageHeader(bytes.data(), 10).has_value()) << ext;
	}
	const uint8_t text[] = "P6 3 2 255\n";
	EXPECT_FALSE(bims::imageHeader(text, sizeof text).has_value());
}

TEST(ImageFile, ReadsWhatImreadReads)
{
	const std::string d = bims::test::freshTmpDir("bims_test_image", "read");
	cv::Mat depth(48, 64, CV_16UC1);
	cv::randu(depth, 0, 65535);
	ASSERT_TRUE(cv::imwrite(d + "/d.png", depth));
	const cv::Mat got = bims::readImageFile(d + "/d.png", cv::IMREAD_UNCHANGED);
	ASSERT_EQ(got.type(), CV_16UC1);
	EXPECT_EQ(cv::countNonZero(got != depth), 0);
	const cv::Mat grey =
	    bims::readImageFile(d + "/d.png", cv::IMREAD_GRAYSCALE);
	EXPECT_EQ(grey.type(), CV_8UC1);
}

// The reproduction of issue 39: a PNG of ~100 bytes declaring 30000 x 30000
// RGBA 16-bit (7.2 GB decoded) is refused from its header.
TEST(ImageFile, ADecompressionBombIsRefusedBeforeDecoding)
{
	const std::string d = bims::test::freshTmpDir("bims_test_image", "bomb");
	bims::test::writePngBomb(d + "/bomb.png");
	const std::string e = errorOf(d + "/bomb.png");
	EXPECT_NE(e.find(d + "/bomb.png: cannot read test image: declares 30000 x "
	                     "30000 pixels in its PNG header"),
	          std::string::npos)
	    << e;
	EXPECT_NE(e.find("not decoded"), std::string::npos) << e;
	// within one limit but not the other: 16384 x 16384 > 2^26 pixels
	bims::test::writePngBomb(d + "/wide.png", 16384, 16384);
	EXPECT_NE(errorOf(d + "/wide.png").find("declares 16384 x 16384"),
	          std::string::npos);
	bims::test::writePngBomb(d + "/side.png", 70000, 10);
	EXPECT_NE(errorOf(d + "/side.png").find("declares 70000 x 10"),
	          std::string::npos);
}

// Issue 55: a FIFO as a depth PNG blocked the import forever; /dev/zero
// was "18446744073709551615 bytes"; a symbolic link loop "no such file".
TEST(ImageFile, AFifoIsRefusedNotWaitedOn)
{
	const std::string d = bims::test::freshTmpDir("bims_test_image", "fifo");
	if (::mkfifo((d + "/fifo.png").c_str(), 0600) != 0)
		GTEST_SKIP() << "mkfifo refused here: " << std::strerror(errno);
	const std::string e = errorOf(d + "/fifo.png");
	EXPECT_NE(e.find(d + "/fifo.png: cannot read test image: a FIFO (named "
	                     "pipe), not a regular file"),
	          std::string::npos)
	    << e;
}

TEST(ImageFile, ADeviceOrALinkLoopIsRefusedNamingWhatItIs)
{
	const std::string d = bims::test::freshTmpDir("bims_test_image", "special");
	const auto has = [](const std::string& e, const std::string& s)
	{ return e.find(s) != std::string::npos; };
	struct stat st;
	if (::stat("/dev/zero", &st) == 0 && S_ISCHR(st.st_mode))
	{
		std::filesystem::create_symlink("/dev/zero", d + "/zero.png");
		EXPECT_TRUE(has(errorOf(d + "/zero.png"),
		                d + "/zero.png: cannot read test image: a character "
		                    "device, not a regular file"))
		    << errorOf(d + "/zero.png");
	}
	std::filesystem::create_symlink("loop2.png", d + "/loop1.png");
	std::filesystem::create_symlink("loop1.png", d + "/loop2.png");
	EXPECT_TRUE(has(errorOf(d + "/loop1.png"), "a symbolic link loop"))
	    << errorOf(d + "/loop1.png");
}

// The refusal of an image's size in the same words for an array (the
// Python module's) as for a file's header (issue 55).
TEST(ImageFile, AnArraysSizeBeyondTheLimitsIsNamedWithTheLimits)
{
	EXPECT_EQ(bims::imageSizeBeyondLimits(16384, 16384, {}),
	          "16384 x 16384 pixels, beyond the 16384 per side and 67108864 "
	          "pixels bims reads ([input] image_max_side, image_max_pixels)");
	EXPECT_EQ(bims::imageSizeBeyondLimits(480, 640, {}), "");
	EXPECT_EQ(bims::imageSizeBeyondLimits(2, 16385, {}).substr(0, 9),
	          "16385 x 2");
	EXPECT_NE(bims::imageSizeBeyondLimits(10, 10, {100, 99, "[input] x"}), "");
}

TEST(ImageFile, EveryOtherBadFileIsAnErrorNamingIt)
{
	const std::string d = bims::test::freshTmpDir("bims_test_image", "bad");
	const auto has = [](const std::string& e, const std::string& s)
	{ return e.find(s) != std::string::npos; };
	EXPECT_TRUE(has(errorOf(d + "/none.png"),
	                d + "/none.png: cannot read test image: no such file"));
	EXPECT_TRUE(has(errorOf(d), "a folder, not a file"));
	std::ofstream(d + "/empty.png");
	EXPECT_TRUE(has(errorOf(d + "/empty.png"), "the file is empty"));
	std::ofstream(d + "/text.png") << "timestamp filename\n";
	EXPECT_TRUE(has(errorOf(d + "/text.png"), "not a PNG, JPEG, TIFF or BMP"));
	// a real PNG cut after its header: the header passes, decoding fails
	std::vector<uint8_t> bytes;
	ASSERT_TRUE(
	    cv::imencode(".png", cv::Mat(40, 40, CV_8UC1, cv::Scalar(7)), bytes));
	std::ofstream(d + "/cut.png", std::ios::binary)
	    .write(reinterpret_cast<const char*>(bytes.data()), 40);
	EXPECT_TRUE(has(errorOf(d + "/cut.png"), "do not decode as PNG"))
	    << errorOf(d + "/cut.png");
	bims::test::writePngBomb(d + "/zero.png", 0, 5);
	EXPECT_TRUE(has(errorOf(d + "/zero.png"), "declares an empty image"));
}
