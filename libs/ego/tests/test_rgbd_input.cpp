// Decoding a 3D scan into an RGB-D frame: unusable scans are refused with
// the reason, never decoded into NaN depth or intrinsics.
#include <bims/ego/rgbd_input.h>
#include <gtest/gtest.h>

#include <limits>

namespace
{
mrpt::obs::CObservation3DRangeScan scan(int w, int h)
{
	mrpt::obs::CObservation3DRangeScan s;
	s.hasRangeImage = true;
	s.rangeImage_setSize(h, w);
	s.rangeImage.fill(1500);
	s.hasIntensityImage = true;
	s.intensityImage.resize(w, h, mrpt::img::CH_GRAY);
	s.intensityImage.filledRectangle(0, 0, w - 1, h - 1,
	                                 mrpt::img::TColor(90, 90, 90));
	s.cameraParams.ncols = w;
	s.cameraParams.nrows = h;
	s.cameraParams.setIntrinsicParamsFromValues(50, 50, w / 2.0, h / 2.0);
	return s;
}
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

TEST(RgbdInput, ASaneScanDecodes)
{
	bims::ego::RgbdFrame f;
	ASSERT_EQ(bims::ego::rgbdFrameFrom(scan(32, 24), {}, f), "");
	EXPECT_FLOAT_EQ(f.depth.at<float>(10, 10), 1.5f);
	EXPECT_DOUBLE_EQ(f.K(0, 0), 50);
}

TEST(RgbdInput, NonFiniteIntrinsicsAreRefused)
{
	for (int k = 0; k < 4; k++)
	{
		auto s = scan(32, 24);
		double fx = 50, fy = 50, cx = 16, cy = 12;
		(k == 0 ? fx : k == 1 ? fy : k == 2 ? cx : cy) = kNaN;
		s.cameraParams.setIntrinsicParamsFromValues(fx, fy, cx, cy);
		bims::ego::RgbdFrame f;
		const auto why = bims::ego::rgbdFrameFrom(s, {}, f);
		EXPECT_NE(why.find("invalid cameraParams"), std::string::npos)
		    << k << ": " << why;
	}
	auto s = scan(32, 24);
	s.cameraParams.setIntrinsicParamsFromValues(
	    std::numeric_limits<double>::infinity(), 50, 16, 12);
	bims::ego::RgbdFrame f;
	EXPECT_NE(bims::ego::rgbdFrameFrom(s, {}, f).find("invalid cameraParams"),
	          std::string::npos);
}

TEST(RgbdInput, NonFiniteOrNonPositiveRangeUnitsAreRefused)
{
	for (float u : {std::numeric_limits<float>::quiet_NaN(), 0.0f, -0.001f,
	                std::numeric_limits<float>::infinity()})
	{
		auto s = scan(32, 24);
		s.rangeUnits = u;
		bims::ego::RgbdFrame f;
		EXPECT_NE(bims::ego::rgbdFrameFrom(s, {}, f).find("invalid rangeUnits"),
		          std::string::npos)
		    << u;
	}
}

TEST(RgbdInput, DepthAndIntensityOfDifferentSizesAreRefused)
{
	auto s = scan(32, 24);
	s.intensityImage.resize(33, 24, mrpt::img::CH_GRAY);
	bims::ego::RgbdFrame f;
	EXPECT_NE(bims::ego::rgbdFrameFrom(s, {}, f).find(
	              "depth 32x24 and intensity 33x24 differ"),
	          std::string::npos);
}

TEST(RgbdInput, AScanWithoutAnImageIsADepthOnlyFrame)
{
	auto s = scan(32, 24);
	s.hasIntensityImage = false;
	bims::ego::RgbdFrame f;
	// a frame decoded before keeps no stale image
	ASSERT_EQ(bims::ego::rgbdFrameFrom(scan(32, 24), {}, f), "");
	ASSERT_TRUE(f.hasImage());
	ASSERT_EQ(bims::ego::rgbdFrameFrom(s, {}, f), "");
	EXPECT_FALSE(f.hasImage());
	EXPECT_EQ(f.size(), cv::Size(32, 24));
	EXPECT_FLOAT_EQ(f.depth.at<float>(10, 10), 1.5f);
	EXPECT_EQ(f.camera().ncols, 32u);
	EXPECT_EQ(f.camera().nrows, 24u);
	// no depth is still refused
	s.hasRangeImage = false;
	EXPECT_EQ(bims::ego::rgbdFrameFrom(s, {}, f), "no range image");
}

TEST(RgbdInput, DecodingIntoAFrameWhoseImagesAreSharedLeavesThemAlone)
{
	// A colour scan (its grey image is the decoder's own buffer).
	auto colour = [](int level, uint16_t raw)
	{
		auto s = scan(32, 24);
		s.rangeImage.fill(raw);
		s.intensityImage.resize(32, 24, mrpt::img::CH_RGB);
		s.intensityImage.filledRectangle(
		    0, 0, 31, 23, mrpt::img::TColor(level, level, level));
		return s;
	};
	bims::ego::RgbdFrame f;
	ASSERT_EQ(bims::ego::rgbdFrameFrom(colour(90, 1500), {}, f), "");
	const bims::ego::RgbdFrame handedOn = f;  // shares f's images
	ASSERT_EQ(bims::ego::rgbdFrameFrom(colour(200, 2500), {}, f), "");
	EXPECT_EQ(handedOn.grey.at<uint8_t>(5, 5), 90);
	EXPECT_FLOAT_EQ(handedOn.depth.at<float>(5, 5), 1.5f);
	EXPECT_EQ(handedOn.raw.at<uint16_t>(5, 5), 1500);
	EXPECT_EQ(f.grey.at<uint8_t>(5, 5), 200);
	EXPECT_FLOAT_EQ(f.depth.at<float>(5, 5), 2.5f);
	EXPECT_EQ(f.raw.at<uint16_t>(5, 5), 2500);
	// a frame nobody else holds keeps its buffers (no allocation per frame)
	const uint8_t* depthBuffer = f.depth.data;
	ASSERT_EQ(bims::ego::rgbdFrameFrom(colour(60, 1000), {}, f), "");
	EXPECT_EQ(f.depth.data, depthBuffer);
	EXPECT_FLOAT_EQ(f.depth.at<float>(5, 5), 1.0f);
}
