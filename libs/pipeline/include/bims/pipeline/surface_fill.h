// Surface fill: a depth surface that the tiers call mostly moving is called
// moving as a whole ([pipeline] surface_fill; docs/pipeline.md, "Surface
// fill"). The tiers decide voxel by voxel from free space: a voxel is moving
// when the space it now occupies was seen free before. The parts of a mover
// whose space was never seen free (it walked in together with the space it
// stands in, or away from the camera over its own earlier place) stay static
// for them. A surface here is a set of pixels connected without a depth jump;
// when enough of one is moving, and it is not a large part of the image (the
// room's floor and walls), all of it is.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace bims::pipeline
{
struct SurfaceFillParams
{
	/** Two neighbouring pixels are on one surface when their depths differ
	 * by less than this share of the larger one. */
	double depthJump = 0.03;
	/** A surface at least this share of whose pixels are moving is moving
	 * whole. */
	double minMoving = 0.3;
	/** A surface larger than this share of the image is never filled. */
	double maxArea = 0.3;
	/** Only the pixels of a filled surface within this distance [m] of one
	 * of its moving pixels (in the image, at the pixel's depth) are filled:
	 * not a floor that a mover's feet join to its legs. */
	double margin = 0.2;
	/** With the direction up in the camera's axes (the IMU's gravity),
	 * pixels whose surface lies within this angle [deg] of horizontal
	 * (floors, table tops) belong to no surface: a mover's feet do not join
	 * it to the floor. 0: off. */
	double horizontalDeg = 30;
};

struct SurfaceFillStats
{
	int surfaces = 0;  ///< surfaces with at least one moving pixel
	int filled = 0;    ///< of them, filled
	int added = 0;     ///< pixels the fill called moving
};

/** Fills \a mask (CV_8UC1, 255 = moving, the size of \a depth) over every
 * surface of \a depth (CV_32FC1 [m], 0 or NaN = no reading; \a K its
 * intrinsics) that the parameters select, within the margin of its
 * moving pixels; \a upC (optional): up in the camera's axes, for
 * horizontalDeg; pixels already moving stay moving, pixels without a
 * reading are never added. Writes into \a mask's own data: clone a mask
 * that shares its data first. Throws std::invalid_argument when the sizes
 * or types differ. */
SurfaceFillStats fillMovingSurfaces(const cv::Mat& depth,
                                    const Eigen::Matrix3d& K, cv::Mat& mask,
                                    const SurfaceFillParams& p,
                                    const Eigen::Vector3d* upC = nullptr);

}  // namespace bims::pipeline
