// Conversion of an RGB-D observation into what the egomotion stage uses: a
// grey image, a metric depth image registered to it, and the intrinsics.
#pragma once

#include <bims/common/depth_image.h>
#include <bims/ego/params.h>
#include <bims/sensors/camera.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <string>

namespace bims::ego
{
/** One RGB-D frame ready for tracking. Registered RGB-D is assumed: depth
 * pixel (u, v) belongs to intensity pixel (u, v) (as in the simulator and in
 * TUM/Bonn imports). A depth-only frame (a scan without an intensity image:
 * a phone's LiDAR without its video, a time-of-flight camera) has an empty
 * grey image: what needs one (the tracker, the optical flow, the
 * photometric term) is skipped for it. */
struct RgbdFrame
{
	double t = 0;   ///< camera timestamp [s]
	cv::Mat grey;   ///< CV_8UC1 of the depth's size, or empty (depth only)
	cv::Mat depth;  ///< CV_32FC1 optical-axis depth [m], 0 = no reading
	Eigen::Matrix3d K = Eigen::Matrix3d::Identity();  ///< intrinsics [px]
	/** The depth readings as read (CV_16UC1, x units [m]; Euclidean ranges
	 * when !rangeIsDepth), depth's source and the voxel cloud's. */
	cv::Mat raw;
	float units = 0;
	bool rangeIsDepth = true;
	mrpt::Clock::time_point stamp{};  ///< t as MRPT's clock (exact)

	/** Whether the frame has an image (else depth only). */
	bool hasImage() const { return !grey.empty(); }
	/** The image size: the depth's. */
	cv::Size size() const { return depth.size(); }

	/** K and the image size: the frame's camera model
	 * (bims/sensors/params.h). */
	sensors::PinholeCamera pinhole() const
	{
		return sensors::PinholeCamera::fromK(K, depth.cols, depth.rows);
	}
	/** The same as MRPT's camera model (what the flow stage takes). */
	mrpt::img::TCamera camera() const { return pinhole().tcamera(); }
	/** The raw readings as a view (valid while the frame lives). */
	DepthImage rawDepth() const;
};

/** Fills \a out from \a obs (intensity -> grey, rangeImage * rangeUnits ->
 * depth, Euclidean ranges converted to depth when range_is_depth = false;
 * K from \a cam when given, else from obs.cameraParams). A scan without an
 * intensity image gives a depth-only frame (grey empty).
 * \return empty string on success, else what is wrong (no range image,
 * sizes differ, camera size disagrees with [camera]). */
[[nodiscard]] std::string rgbdFrameFrom(
    const mrpt::obs::CObservation3DRangeScan& obs, const CameraParams& cam,
    RgbdFrame& out);
/** The same from a depth image (its readings are copied), an image (BGR
 * or grey, 8-bit, the depth's size; empty: depth only) and the intrinsics
 * \a K; out.t from the depth's timestamp when it has one. What the scan's
 * version does after reading the scan. */
[[nodiscard]] std::string rgbdFrameFrom(const DepthImage& depth,
                                        const cv::Mat& image,
                                        const Eigen::Matrix3d& K,
                                        RgbdFrame& out);

/** Depth at a sub-pixel position [m]: bilinear over the 4 neighbours if all
 * are valid and within 5 % of each other (no interpolation across depth
 * edges), else 0. */
float depthAt(const cv::Mat& depth, const cv::Point2f& x);

/** Back-projection of pixel \a x at depth \a z [m] into the optical frame. */
Eigen::Vector3d backProject(const Eigen::Matrix3d& K, const cv::Point2f& x,
                            double z);

}  // namespace bims::ego
