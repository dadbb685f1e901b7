// KeyframeAnchor: map-anchored tracking. Keeps keyframes of the static scene
// (RGB-D frames with their world pose, their moving content excluded) and
// aligns every new frame densely (alignDense) to the keyframe nearest its
// predicted pose, so that the pose is measured against the static scene,
// not chained from the previous frame: drift does not accumulate while the
// camera stays among its keyframes, and people (absent from the keyframes,
// or masked out of them) do not pull the pose.
//
// Timing: a frame becomes a keyframe one frame late (addPending() at the
// next frame), when its moving mask from the segmentation is known.
#pragma once

#include <bims/ego/dense_align.h>
#include <bims/ego/params.h>
#include <bims/ego/rgbd_input.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <deque>
#include <functional>
#include <vector>

namespace bims::ego
{
/** What the anchor did with one frame. */
struct AnchorResult
{
	bool tried = false;     ///< a keyframe was available and aligned to
	bool accepted = false;  ///< the anchored pose replaces the prediction
	std::string why;        ///< why not accepted (empty when accepted)
	Eigen::Matrix3d R_WC = Eigen::Matrix3d::Identity();  ///< anchored pose
	Eigen::Vector3d t_WC = Eigen::Vector3d::Zero();
	int keyframe = -1;            ///< id of the keyframe aligned to
	int points = 0, inliers = 0;  ///< of the alignment (finest level)
	double inlier_fraction = 0, overlap = 0, coverage = 0;
	int guess = 0;  ///< 0: the prediction won, k: others[k - 1]
	/** Keyframe readings this frame saw through (dropped from it). */
	int seen_through = 0;
	double correction_m = 0, correction_deg = 0;  ///< anchored vs predicted
	/** The information the alignment's data alone give about the position
	 * t_WC (world frame [1/m^2]; the rotation marginalised with its prior),
	 * of the alignment that anchored the frame (or of the last tried). */
	Eigen::Matrix3d position_information = Eigen::Matrix3d::Zero();
	/** Share of the frame's pixels excluded by the moving mask (set by the
	 * caller, Odometry, that judges the mask). */
	double excluded_fraction = 0;
	/** The mask was not used: too large, or the alignment failed with it
	 * and was accepted without it. */
	bool maskIgnored = false;
	/** Refused by the caller's gate (the inertial prediction): the
	 * alignment disagreed with it beyond its uncertainty. */
	bool gated = false;
	/** Accepted with a correction beyond max_correction_* (the frame fits
	 * the keyframe almost entirely: the pose had drifted). */
	bool relocalised = false;
	cv::Mat outliers;  ///< alignment outliers (finest level), or empty
	double ms = 0;     ///< time of this frame's anchoring [ms]
};

/** The caller's test of an alignment it is offered: the anchored t_WC and
 * the information its data give about it (world frame); false refuses it
 * (AnchorResult::gated) and the other keyframes are tried. */
using AnchorGate = std::function<bool(const Eigen::Vector3d& t_WC,
                                      const Eigen::Matrix3d& information_W)>;

class KeyframeAnchor
{
 public:
	explicit KeyframeAnchor(const AnchorParams& p);

	/** Aligns \a f to the keyframe nearest the predicted pose (R_pred,
	 * t_pred) = T_WC. \param others more initial guesses of T_WC (e.g. the
	 * constant-velocity one; the best at the coarsest level goes on).
	 * \param R_prior rotation prior (T_WC's rotation, e.g. the IMU's), or
	 * nullptr. \param tPrior prior on t_WC (world frame: the inertial
	 * prediction), or nullptr. \param gate the caller's test of an
	 * alignment before it is accepted (AnchorGate), or nullptr.
	 * \param moving CV_8UC1 pixels of \a f predicted moving
	 * (excluded; the caller judged it not too large), or empty. An
	 * alignment that fails with it is tried once more without it
	 * (maskIgnored). Keeps \a f for addPending(). */
	AnchorResult track(const RgbdFrame& f, const Eigen::Matrix3d& R_pred,
	                   const Eigen::Vector3d& t_pred,
	                   const std::vector<InitialGuess>& others,
	                   const Eigen::Matrix3d* R_prior, const cv::Mat& moving,
	                   const TranslationPrior* tPrior = nullptr,
	                   const AnchorGate* gate = nullptr);

	/** Whether the frame of the last track() should become a keyframe at
	 * (R_WC, t_WC) (its final pose): no keyframe yet, its keyframe covers
	 * too little of it (coverage), or it is too far from its keyframe.
	 * Remembers the decision. */
	bool wantKeyframe(const AnchorResult& r, const Eigen::Matrix3d& R_WC,
	                  const Eigen::Vector3d& t_WC, bool force = false);

	/** Makes the frame kept by the last wantKeyframe() == true a keyframe;
	 * \a moving (CV_8UC1 of its size, or empty) and its alignment
	 * outliers are excluded. Returns false when nothing was pending. */
	bool addPending(const cv::Mat& moving);

	/** The geometry's veto of a fed-back moving mask (AnchorParams::
	 * mask_veto_consistent): \a moving (CV_8UC1, non-zero = moving) of the
	 * frame of the last track() without its connected regions whose samples
	 * that alignment found on the static keyframe's surface at least that
	 * often (among those it found on it or off it). \a moving itself when
	 * the veto is off, the last alignment was not accepted, or \a moving is
	 * not of its size. \param vetoed gets the share of \a moving's pixels
	 * left out. */
	cv::Mat vetoMask(const cv::Mat& moving, double* vetoed = nullptr) const;

	size_t keyframes() const { return kf_.size(); }
	void clear();

 private:
	struct Keyframe
	{
		int id = 0;
		DenseFrame frame;
		Eigen::Matrix3d R_WK;
		Eigen::Vector3d t_WK;
	};
	Keyframe* nearest(const Eigen::Matrix3d& R_WC, const Eigen::Vector3d& t_WC,
	                  const std::vector<Keyframe*>& skip = {});
	/** One alignment of the frame to a keyframe, before it is taken. */
	struct Attempt
	{
		AnchorResult r;  ///< accepted or why not
		Keyframe* k = nullptr;
		cv::Mat consistent;            ///< DenseAlignResult::consistent
		std::vector<int> seenThrough;  ///< of k's finest level, if accepted
	};
	/** Aligns the frame in cur_ to \a k; \a start gives the fields an
	 * alignment does not set (the prediction when not accepted). */
	Attempt alignTo(Keyframe& k, const Eigen::Matrix3d& R_pred,
	                const Eigen::Vector3d& t_pred,
	                const std::vector<InitialGuess>& others,
	                const Eigen::Matrix3d* R_prior, const AnchorResult& start,
	                const TranslationPrior* tPrior, const AnchorGate* gate);
	/** Takes the chosen alignment, when accepted: its outlier and
	 * consistent images (the keyframe the frame may become, the veto) and
	 * what the frame saw through of its keyframe dropped from it. */
	void take(Attempt& a);

	AnchorParams p_;
	std::deque<Keyframe> kf_;
	int nextId_ = 0;
	// the last tracked frame (in cur_), and whether it is to become a
	// keyframe
	bool haveLast_ = false;
	cv::Mat lastOutliers_;
	cv::Mat lastConsistent_;  // of the last accepted alignment
	bool pending_ = false;
	Eigen::Matrix3d R_pending_ = Eigen::Matrix3d::Identity();
	Eigen::Vector3d t_pending_ = Eigen::Vector3d::Zero();
	DenseFrame cur_;  // reused buffers
};

}  // namespace bims::ego
