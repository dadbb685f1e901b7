#include <bims/common/frames.h>
#include <gtest/gtest.h>

TEST(Frames, T_SCMatchesTheAxisPermutation)
{
	const mrpt::math::TPoint3D p_C(0.3, -0.2, 2.0);
	const auto p_S = bims::T_SC().composePoint(p_C);
	const auto q_S = bims::scanFromOptical(p_C);
	EXPECT_NEAR(p_S.x, q_S.x, 1e-12);
	EXPECT_NEAR(p_S.y, q_S.y, 1e-12);
	EXPECT_NEAR(p_S.z, q_S.z, 1e-12);
	EXPECT_NEAR(p_S.x, 2.0, 1e-12);   // forward
	EXPECT_NEAR(p_S.y, -0.3, 1e-12);  // optical right = scan -left
	const auto back = bims::opticalFromScan(p_S);
	EXPECT_NEAR(back.x, p_C.x, 1e-12);
	EXPECT_NEAR(back.y, p_C.y, 1e-12);
	EXPECT_NEAR(back.z, p_C.z, 1e-12);
}
