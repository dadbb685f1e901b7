// fillMovingSurfaces: which surfaces are filled, how far, and what never is.
#include <bims/pipeline/surface_fill.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using bims::pipeline::fillMovingSurfaces;
using bims::pipeline::SurfaceFillParams;

namespace
{
constexpr int kW = 160, kH = 120;

Eigen::Matrix3d intrinsics()
{
	Eigen::Matrix3d K;
	K << 150, 0, 80, 0, 150, 60, 0, 0, 1;
	return K;
}

/** A wall at 3 m with a box at 1.5 m in front of it (cols 40-79, rows
 * 30-89: 2400 pixels, 4 % of the image). */
cv::Mat wallAndBox()
{
	cv::Mat d(kH, kW, CV_32FC1, cv::Scalar(3.0f));
	d(cv::Rect(40, 30, 40, 60)).setTo(1.5f);
	return d;
}

int count(const cv::Mat& m, const cv::Rect& r)
{
	return cv::countNonZero(m(r));
}
}  // namespace

TEST(SurfaceFill, AMostlyMovingSurfaceIsFilledWholeAndNothingBeyondItsEdges)
{
	const cv::Mat depth = wallAndBox();
	cv::Mat mask(kH, kW, CV_8UC1, cv::Scalar(0));
	const cv::Rect box(40, 30, 40, 60);
	mask(cv::Rect(40, 30, 40, 24)).setTo(255);  // 40 % of the box
	SurfaceFillParams p;
	p.margin = 1.0;  // 100 pixels at 1.5 m: the whole box
	const auto st = fillMovingSurfaces(depth, intrinsics(), mask, p);
	EXPECT_EQ(count(mask, box), box.area());        // its rim pixels too
	EXPECT_EQ(cv::countNonZero(mask), box.area());  // not the wall
	EXPECT_EQ(st.surfaces, 1);
	EXPECT_EQ(st.filled, 1);
	EXPECT_EQ(st.added, box.area() - 40 * 24);
}

TEST(SurfaceFill, ASurfaceWithTooFewMovingPixelsOrTooLargeStaysAsItWas)
{
	const cv::Mat depth = wallAndBox();
	cv::Mat mask(kH, kW, CV_8UC1, cv::Scalar(0));
	mask(cv::Rect(40, 30, 40, 12)).setTo(255);  // 20 % of the box
	const cv::Mat before = mask.clone();
	const auto st = fillMovingSurfaces(depth, intrinsics(), mask, {});
	EXPECT_EQ(cv::norm(mask, before, cv::NORM_L1), 0.0);
	EXPECT_EQ(st.filled, 0);

	// The wall is 96 % of the image: never filled, however much moves.
	SurfaceFillParams p;
	p.minMoving = 0.01;
	p.margin = 100;
	mask.setTo(0);
	mask(cv::Rect(100, 0, 60, kH)).setTo(255);
	const cv::Mat wallBefore = mask.clone();
	fillMovingSurfaces(depth, intrinsics(), mask, p);
	EXPECT_EQ(cv::norm(mask, wallBefore, cv::NORM_L1), 0.0);
	// With a larger limit it is.
	p.maxArea = 1.0;
	fillMovingSurfaces(depth, intrinsics(), mask, p);
	EXPECT_GT(cv::countNonZero(mask), kW * kH - 2400 - 300);
	EXPECT_EQ(count(mask, cv::Rect(42, 32, 36, 56)), 0);  // not the box
}

TEST(SurfaceFill, OnlyPixelsWithinTheMarginOfAMovingPixelAreFilled)
{
	// A 1 m deep plane seen at 2 m: a pixel is 2 / 150 = 13.3 mm there.
	cv::Mat depth(kH, kW, CV_32FC1, cv::Scalar(2.0f));
	cv::Mat mask(kH, kW, CV_8UC1, cv::Scalar(0));
	mask(cv::Rect(0, 0, kW, 40)).setTo(255);  // a third of the image
	SurfaceFillParams p;
	p.maxArea = 1.0;
	p.margin = 0.2;  // 15 pixels at 2 m
	fillMovingSurfaces(depth, intrinsics(), mask, p);
	// Distances are taken on blocks of 4 x 4 pixels: to within a block.
	EXPECT_EQ(count(mask, cv::Rect(0, 40, kW, 11)), kW * 11);
	EXPECT_EQ(count(mask, cv::Rect(0, 59, kW, kH - 59)), 0);
	// A larger margin reaches farther.
	p.margin = 0.5;  // 37.5 pixels
	mask.setTo(0);
	mask(cv::Rect(0, 0, kW, 40)).setTo(255);
	fillMovingSurfaces(depth, intrinsics(), mask, p);
	EXPECT_EQ(count(mask, cv::Rect(0, 40, kW, 33)), kW * 33);
	EXPECT_EQ(count(mask, cv::Rect(0, 82, kW, kH - 82)), 0);
}

TEST(SurfaceFill, PixelsWithoutAReadingAreNeverAddedAndSeparateSurfaces)
{
	cv::Mat depth = wallAndBox();
	const float nan = std::numeric_limits<float>::quiet_NaN();
	// Holes inside the box; and a column of holes splitting it in two.
	depth(cv::Rect(50, 40, 5, 5)).setTo(0.0f);
	depth(cv::Rect(65, 60, 3, 3)).setTo(nan);
	depth(cv::Rect(59, 30, 2, 60)).setTo(0.0f);
	cv::Mat mask(kH, kW, CV_8UC1, cv::Scalar(0));
	mask(cv::Rect(40, 30, 19, 60)).setTo(0);
	mask(cv::Rect(61, 30, 19, 30)).setTo(255);  // half of the right part
	SurfaceFillParams p;
	p.margin = 1.0;
	const auto st = fillMovingSurfaces(depth, intrinsics(), mask, p);
	EXPECT_EQ(count(mask, cv::Rect(61, 30, 19, 60)), 19 * 60 - 9);
	EXPECT_EQ(count(mask, cv::Rect(65, 60, 3, 3)), 0);
	EXPECT_EQ(count(mask, cv::Rect(40, 30, 21, 60)), 0);  // the left part
	EXPECT_EQ(st.filled, 1);
}

TEST(SurfaceFill, DepthJumpsSeparateSurfacesAndSlopesDoNot)
{
	// A ramp from 1 m to 2 m over the columns (under 1 % per pixel), with a
	// 10 % step at column 80.
	cv::Mat depth(kH, kW, CV_32FC1);
	for (int x = 0; x < kW; ++x)
		depth.col(x).setTo(1.0f + x / 160.0f + (x >= 80 ? 0.15f : 0.0f));
	cv::Mat mask(kH, kW, CV_8UC1, cv::Scalar(0));
	mask(cv::Rect(0, 0, 40, kH)).setTo(255);
	SurfaceFillParams p;
	p.maxArea = 1.0;
	p.margin = 100;
	fillMovingSurfaces(depth, intrinsics(), mask, p);
	EXPECT_EQ(count(mask, cv::Rect(0, 0, 80, kH)), 80 * kH);
	EXPECT_EQ(count(mask, cv::Rect(80, 0, 80, kH)), 0);
}

TEST(SurfaceFill, WithGravityAFloorJoinsNoSurfaceAndIsNeverFilled)
{
	// The camera 1 m above a floor, looking level (y down): floor row v at
	// depth 150 / (v - 60); a box 3 m away standing on it (columns 60-99,
	// rows 70-109, 0.2-1.0 m below the camera), its foot at the floor's
	// depth: one surface without gravity.
	cv::Mat depth(kH, kW, CV_32FC1, cv::Scalar(0.0f));
	for (int v = 61; v < kH; ++v)
		depth.row(v).setTo(150.0f / static_cast<float>(v - 60));
	const cv::Rect box(60, 70, 40, 40);
	depth(box).setTo(3.0f);
	cv::Mat mask(kH, kW, CV_8UC1, cv::Scalar(0));
	mask(cv::Rect(60, 70, 40, 16)).setTo(255);  // 40 % of the box
	SurfaceFillParams p;
	p.maxArea = 0.2;
	p.margin = 10;
	// Without gravity the box and the floor are one surface, too large.
	cv::Mat noUp = mask.clone();
	EXPECT_EQ(fillMovingSurfaces(depth, intrinsics(), noUp, p).filled, 0);
	EXPECT_EQ(cv::countNonZero(noUp), 40 * 16);
	// With it the floor is cut away: the box alone is filled, the floor
	// not at all (its foot's two rows are where the normals mix).
	const Eigen::Vector3d up(0, -1, 0);
	cv::Mat withUp = mask.clone();
	const auto st = fillMovingSurfaces(depth, intrinsics(), withUp, p, &up);
	EXPECT_EQ(st.filled, 1);
	EXPECT_EQ(count(withUp, cv::Rect(60, 70, 40, 38)), 40 * 38);
	EXPECT_EQ(count(withUp, cv::Rect(0, 110, kW, kH - 110)), 0);
	EXPECT_EQ(cv::countNonZero(withUp(cv::Rect(0, 0, 60, kH))), 0);
	// horizontalDeg = 0: off, as without gravity.
	p.horizontalDeg = 0;
	cv::Mat off = mask.clone();
	EXPECT_EQ(fillMovingSurfaces(depth, intrinsics(), off, p, &up).filled, 0);
}

TEST(SurfaceFill, WrongTypesOrSizesAreRefused)
{
	cv::Mat mask(kH, kW, CV_8UC1, cv::Scalar(255));
	cv::Mat d16(kH, kW, CV_16UC1, cv::Scalar(1000));
	EXPECT_THROW(fillMovingSurfaces(d16, intrinsics(), mask, {}),
	             std::invalid_argument);
	cv::Mat small(kH / 2, kW, CV_32FC1, cv::Scalar(1.0f));
	EXPECT_THROW(fillMovingSurfaces(small, intrinsics(), mask, {}),
	             std::invalid_argument);
}
