#include <bims/eval/pose_utils.h>
#include <gtest/gtest.h>

#include <cmath>

namespace ev = bims::eval;
using mrpt::poses::CPose3D;

TEST(PoseUtils, InterpolationMidpointAndLimits)
{
	bims::Trajectory t = {{0.0, CPose3D(0, 0, 0, 0, 0, 0)},
	                      {1.0, CPose3D(2, 0, 0, mrpt::DEG2RAD(90.0), 0, 0)},
	                      {5.0, CPose3D(3, 0, 0, 0, 0, 0)}};
	const auto p = ev::interpolatePose(t, 0.5, 2.0);
	ASSERT_TRUE(p);
	EXPECT_NEAR(p->x(), 1.0, 1e-12);
	EXPECT_NEAR(p->yaw(), mrpt::DEG2RAD(45.0), 1e-9);
	EXPECT_FALSE(ev::interpolatePose(t, -0.1, 2.0));
	EXPECT_FALSE(ev::interpolatePose(t, 5.1, 2.0));
	EXPECT_FALSE(ev::interpolatePose(t, 3.0, 2.0));  // gap of 4 s > 2 s
	ASSERT_TRUE(ev::interpolatePose(t, 5.0, 2.0));   // exact stamp
	EXPECT_NEAR(ev::interpolatePose(t, 5.0, 2.0)->x(), 3.0, 1e-12);
}

TEST(PoseUtils, BonnConversionMatchesTheFormula)
{
	// T_WC = T_gt T_ros T_m: for T_gt = identity, the rotation is T_ros times
	// T_m's (orthonormalised) and the translation T_ros t_m = (-tx, tz, ty).
	const CPose3D T = ev::bonnMarkerToCamera(CPose3D());
	const double* m = ev::bonnTm4x4();
	EXPECT_NEAR(T.x(), -m[3], 1e-12);
	EXPECT_NEAR(T.y(), m[11], 1e-12);
	EXPECT_NEAR(T.z(), m[7], 1e-12);
	const auto R = T.getRotationMatrix();
	EXPECT_NEAR(R.det(), 1.0, 1e-9);
	const int rowOf[3] = {0, 2, 1};
	const double sign[3] = {-1, 1, 1};
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++)
			EXPECT_NEAR(R(r, c), sign[r] * m[4 * rowOf[r] + c], 0.1);
	// The marker's translation passes through unchanged (world = mocap).
	const CPose3D T2 = ev::bonnMarkerToCamera(CPose3D(1, 2, 3, 0, 0, 0));
	EXPECT_NEAR(T2.x() - T.x(), 1.0, 1e-12);
	EXPECT_NEAR(T2.y() - T.y(), 2.0, 1e-12);
	EXPECT_NEAR(T2.z() - T.z(), 3.0, 1e-12);
}
