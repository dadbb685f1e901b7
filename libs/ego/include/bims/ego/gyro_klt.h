// GyroAidedKLT: pyramidal Lucas-Kanade feature tracking (OpenCV) whose
// initial guess for each feature is its position predicted from the
// inter-frame camera rotation: x_cur ~ H x_prev with the infinite homography
// H = K R_CcurCprev K^-1 (exact for a pure rotation or distant points).
// Forward-backward check, grid-distributed replenishment (FAST or
// goodFeaturesToTrack) and an input mask that excludes the regions labelled
// moving in the previous frame. The aid is a per-call choice (pass no
// rotation for plain LK with the same pyramid and window), so that its value
// can be measured. No threads, no I/O.
#pragma once

#include <bims/ego/params.h>

#include <Eigen/Core>
#include <Eigen/LU>
#include <opencv2/core.hpp>

#include <vector>

namespace bims::ego
{
/** A feature followed from the previous frame to the current one. */
struct Track
{
	int id = -1;            ///< feature id, unique over the tracker's life
	int age = 0;            ///< frames this feature has been tracked
	cv::Point2f prev;       ///< position in the previous image [px]
	cv::Point2f cur;        ///< tracked position in the current image [px]
	cv::Point2f predicted;  ///< LK initial guess in the current image [px]
};

/** Counters of one track() call. */
struct TrackerStats
{
	int attempted = 0;    ///< features from the previous frame tried
	int tracked = 0;      ///< survived LK status, border and FB check
	int lostFb = 0;       ///< rejected by the forward-backward check
	int droppedMask = 0;  ///< dropped in the previous moving mask
	int detected = 0;     ///< new features added on the current frame
};

/** \a mask (CV_8UC1) dilated by an ellipse of radius \a px: the same as
 * cv::dilate over the whole image, computed around the non-zero pixels only
 * (an empty mask costs nothing). */
cv::Mat dilateMask(const cv::Mat& mask, int px);

class GyroAidedKLT
{
 public:
	explicit GyroAidedKLT(const TrackerParams& p = {});

	/** Tracks the features of the previous frame into \a grey and then
	 * replenishes features on \a grey for the next call.
	 * \param grey CV_8UC1 image; all frames must have the same size.
	 * \param K camera intrinsics [px] of this image.
	 * \param R_CprevC the current camera {C_cur} expressed in the
	 *        previous one {C_prev} (from the gyro), or nullptr for unaided
	 *        LK (initial guess = previous position).
	 * \param movingMaskPrev CV_8UC1, same size, non-zero = labelled moving
	 *        in the previous frame, or nullptr.
	 * \return the successful tracks (empty on the first frame).
	 * \throws std::invalid_argument on a wrong image type/size. */
	const std::vector<Track>& track(const cv::Mat& grey,
	                                const Eigen::Matrix3d& K,
	                                const Eigen::Matrix3d* R_CprevC,
	                                const cv::Mat* movingMaskPrev);

	/** The infinite homography H = K R_CcurCprev K^-1, x_cur ~ H x_prev. */
	static Eigen::Matrix3d infiniteHomography(const Eigen::Matrix3d& K,
	                                          const Eigen::Matrix3d& R_CprevC);
	/** Applies a homography to a pixel. */
	static cv::Point2f warp(const Eigen::Matrix3d& H, const cv::Point2f& x);

	const TrackerStats& stats() const { return stats_; }
	/** Positions in the previous image of the features the last call tried
	 * to track (tracked or lost) [px]. */
	const std::vector<cv::Point2f>& attemptedPoints() const { return tried_; }
	/** Number of features alive after the last call. */
	size_t numFeatures() const { return pts_.size(); }
	/** Forgets all features and the previous image. */
	void reset();
	const TrackerParams& params() const { return p_; }

 private:
	/** Checks the image and the mask; the mask to use (null: none). */
	const cv::Mat* checkedMask(const cv::Mat& grey,
	                           const cv::Mat* movingMaskPrev) const;
	/** The previous features not on \a mask; \a idx their indices. */
	std::vector<cv::Point2f> featuresOffMask(const cv::Mat* mask, cv::Size size,
	                                         std::vector<int>& idx);
	/** Tracks tried_ (the features at \a idx) into \a pyr: tracks_, and
	 * the features kept for the next frame. */
	void follow(const std::vector<cv::Mat>& pyr, cv::Size size,
	            const Eigen::Matrix3d& K, const Eigen::Matrix3d* R_CprevC,
	            const std::vector<int>& idx);
	void replenish(const cv::Mat& grey, const cv::Mat* movingMask);

	TrackerParams p_;
	std::vector<cv::Mat> prevPyr_;
	cv::Size size_;
	std::vector<cv::Point2f> pts_;  // features in the previous image
	std::vector<int> ids_, ages_;
	std::vector<Track> tracks_;
	std::vector<cv::Point2f> tried_;
	TrackerStats stats_;
	int nextId_ = 0;
};

}  // namespace bims::ego
