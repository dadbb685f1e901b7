// Frames of reference used across bims (see docs/architecture.md).
//
//  {W} world: gravity-aligned, z up, x towards magnetic north, y west (NWU).
//  {I} IMU body frame (the sensor's own axes).
//  {C} camera optical frame: x right, y down, z forward (OpenCV, TUM files).
//  {S} MRPT's 3D-scan sensor frame: x forward, y left, z up. Points from
//      CObservation3DRangeScan::unprojectInto() (with sensorPose = identity)
//      are in {S}.
//  {R} the camera frame rotated to {W}'s axes (differs from {W} by a
//      translation only).
// Every pose is named T_AB: frame {B} expressed in {A}, so p_A = T_AB * p_B.
#pragma once

#include <mrpt/math/TPoint3D.h>
#include <mrpt/poses/CPose3D.h>

namespace bims
{
/** T_SC: the optical frame {C} in MRPT's scan frame {S}
 * (yaw -90 deg, roll -90 deg). */
inline const mrpt::poses::CPose3D& T_SC()
{
	static const mrpt::poses::CPose3D T(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
	return T;
}

/** p_C (optical) from p_S (MRPT scan frame): x_C=-y_S, y_C=-z_S, z_C=x_S. */
inline mrpt::math::TPoint3D opticalFromScan(const mrpt::math::TPoint3D& p_S)
{
	return {-p_S.y, -p_S.z, p_S.x};
}
/** p_S (MRPT scan frame) from p_C (optical). */
inline mrpt::math::TPoint3D scanFromOptical(const mrpt::math::TPoint3D& p_C)
{
	return {p_C.z, -p_C.x, -p_C.y};
}

/** Standard gravity [m/s^2]; gravity in {W} is (0, 0, -kGravity). */
constexpr double kGravity = 9.80665;

}  // namespace bims
