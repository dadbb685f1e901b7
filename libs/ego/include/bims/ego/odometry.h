// Odometry: the egomotion stage, one call per RGB-D frame.
//
//   addImu()       feeds the attitude filter (R_WI, docs/attitude.md).
//   processFrame() gyro-aided KLT between the previous and this frame,
//                  features with depth -> 3D correspondences, then either
//                  mode = imu:    R_WC = R_WI(t + time_offset) R_IC and the
//                                 translation from the rotation-compensated
//                                 features (optionally refined with SE(3));
//                  mode = vision: full SE(3) from the 3D features (RANSAC).
// Then ([anchor] enable) the pose is aligned densely to a keyframe of the
// static scene (KeyframeAnchor): the frame-to-frame estimate is only its
// initial guess (and the IMU rotation its prior).
// The moving-region mask of the previous frame (from the segmentation) keeps
// features off independently moving objects and out of the keyframe the
// previous frame may become; predicted into this frame with the
// frame-to-frame motion (moving_prediction.h), it keeps them out of the
// alignment. No threads, no I/O.
#pragma once

#include <bims/ego/attitude_filter.h>
#include <bims/ego/gyro_klt.h>
#include <bims/ego/inertial_filter.h>
#include <bims/ego/keyframe_anchor.h>
#include <bims/ego/params.h>
#include <bims/ego/rgbd_input.h>
#include <bims/ego/translation_estimator.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/poses/CPose3D.h>

#include <optional>
#include <vector>

namespace bims::ego
{
/** Where a frame's rotation came from. */
enum class RotationSource
{
	None,        ///< first frame without IMU, or failure fallback
	Imu,         ///< attitude filter (R_WI R_IC)
	ImuRefined,  ///< IMU prior fused with the features (refine = se3)
	Vision,      ///< tracked 3D features only
};
const char* toString(RotationSource s);

/** The egomotion of one frame. */
struct FrameEgomotion
{
	double t = 0;                   ///< camera timestamp [s]
	mrpt::poses::CPose3D T_WC;      ///< camera in the world
	mrpt::poses::CPose3D T_CprevC;  ///< this camera in the previous one
	RotationSource R_source = RotationSource::None;
	uint32_t flags = 0;         ///< kFlag* bits (flags.h); 0 = all good
	int correspondences = 0;    ///< tracks with depth in both frames
	int inliers = 0;            ///< of the robust fit
	double residual_rms_m = 0;  ///< RMS 3D residual of the inliers [m]
	std::vector<Track> tracks;  ///< KLT tracks previous -> this frame
	/** Per track: 1 inlier, 0 outlier (candidate moving), -1 no depth. */
	std::vector<int8_t> trackInlier;
	/** What the map anchoring did ([anchor]; tried = false when off). */
	AnchorResult anchor;
	/** Share of the fed-back moving mask's pixels the geometry vetoed
	 * (KeyframeAnchor::vetoMask; kFlagMaskVetoed). */
	double mask_vetoed = 0;
	/** The depth-inertial translation ([inertial]): whether the filter
	 * carried this frame, the directions of its position the alignment left
	 * unconstrained (-1: no alignment analysed), its innovation (NIS) and
	 * the filter's velocity and accelerometer bias after the frame. */
	bool inertial = false;
	int degenerate = -1;
	double inertial_nis = 0;
	/** Eigenvalues of the alignment's position information as the filter
	 * took it, ascending [1/m^2]. */
	Eigen::Vector3d position_information = Eigen::Vector3d::Zero();
	Eigen::Vector3d v_W = Eigen::Vector3d::Zero();       ///< [m/s]
	Eigen::Vector3d acc_bias = Eigen::Vector3d::Zero();  ///< {I} [m/s^2]
	/** Gravity in the odometry's world as the filter estimates it [m/s^2]
	 * (the world's vertical is the attitude filter's first one). */
	Eigen::Vector3d gravity_W = Eigen::Vector3d::Zero();
	double ms_input = 0, ms_track = 0, ms_motion = 0;  ///< stage times [ms]
	double ms_anchor = 0;  ///< of ms_motion: the keyframe alignment [ms]
	TrackerStats tracker;  ///< KLT counters of this frame
	/** Previous-image positions of all features the KLT tried [px]. */
	std::vector<cv::Point2f> attempted;

	/** true when the motion was measured (no failure flag). */
	bool ok() const;
	/** true when the pose was measured against the static scene (or is the
	 * first frame's, which defines the world): ok(), and not every keyframe
	 * alignment refused by the IMU's gate (the pose then is the inertial
	 * prediction, which nothing checked). */
	bool registered() const;
};

class Odometry
{
 public:
	explicit Odometry(const EgoConfig& cfg);

	/** Feeds an IMU observation (ignored when its label does not match
	 * [sensors] imu_label). Returns kFlag* bits of the sample. */
	uint32_t addImu(const mrpt::obs::CObservationIMU& obs);
	/** Same, for an already converted sample (IMU clock). */
	uint32_t addImu(const ImuSample& s);

	/** Processes one RGB-D observation. \param movingMaskPrev CV_8UC1 of
	 * the image size, non-zero = moving in the previous frame, or nullptr.
	 * A frame whose images cannot be used is flagged kFlagBadImage. */
	FrameEgomotion processFrame(const mrpt::obs::CObservation3DRangeScan& obs,
	                            const cv::Mat* movingMaskPrev = nullptr);
	/** Same, for an already converted frame. */
	FrameEgomotion processFrame(const RgbdFrame& f,
	                            const cv::Mat* movingMaskPrev = nullptr);

	/** Replaces the motion of the frame processed last by \a T_CprevC
	 * (e.g. refined against the dense optical flow): its T_WC and the motion
	 * the next frame falls back on follow (also while the attitude filter
	 * converges, when processFrame() takes the filter's absolute attitude;
	 * attitude_blend pulls R_WC back towards the filter's in later frames).
	 * Returns the new T_WC. Does
	 * nothing (returns the current T_WC) when the last frame estimated no
	 * motion (first frame, out-of-order or unusable frame), or when that
	 * frame was anchored to a keyframe: the anchored pose is measured
	 * against the static scene and stays. */
	mrpt::poses::CPose3D correctLastMotion(
	    const mrpt::poses::CPose3D& T_CprevC);

	/** R_WC at camera time t from the IMU (nullopt without IMU data or
	 * R_IC); *flags gets kFlagImuMissing / kFlagImuGap. \param gyroOnly
	 * use the gyro-only chain (for inter-frame rotations). */
	std::optional<Eigen::Matrix3d> imuRotation(double tCam,
	                                           uint32_t* flags = nullptr,
	                                           bool gyroOnly = false) const;

	/** The rotation R_{C(t-1)C(t)} expected for the next frame, stamped
	 * \a tCam, before processFrame() measures it: the gyro chain's rotation
	 * over the interval when IMU data cover it, else the last frame's
	 * rotation (constant velocity); identity before the first frame. Changes
	 * nothing: the pipeline derotates the observed flow with it while the
	 * egomotion runs. */
	Eigen::Matrix3d predictRotation(double tCam) const;

	const AttitudeFilter& attitude() const { return att_; }
	const EgoConfig& config() const { return cfg_; }
	size_t framesProcessed() const { return nFrames_; }

 private:
	/** What the IMU says of a frame at camera time t: R_WC from the attitude
	 * filter, from the gyro chain alone, the gyro's rotation since the
	 * previous frame, and the IMU's kFlag* bits. */
	struct ImuPrediction
	{
		std::optional<Eigen::Matrix3d> R_WC, R_WC_gyro, R_rel_gyro;
		uint32_t flags = 0;
	};
	/** The frame-to-frame motion of a frame and how it was reached. */
	struct FrameToFrame
	{
		Eigen::Matrix3d R_rel;  ///< R_CprevC
		Eigen::Vector3d t_rel;  ///< t_CprevC
		bool useImu = false;    ///< the rotation is the IMU's
		/** the IMU's first attitude: the world turns to it this frame */
		bool reanchorWorld = false;
		bool filterConverging = false;  ///< the attitude filter converges
	};

	// The steps of processFrame, in order.
	/** The previous frame's mask as the tracker takes it: guarded
	 * (tooLarge), vetoed by the geometry; the previous frame becomes a
	 * keyframe with it. Empty: none. */
	cv::Mat takeMovingMask(const cv::Mat* mask, FrameEgomotion& r);
	ImuPrediction predictFromImu(double t) const;
	/** The first frame: the reference pose (the IMU's attitude if any). */
	FrameEgomotion firstFrame(const RgbdFrame& f, const ImuPrediction& imu,
	                          const cv::Mat* mask, FrameEgomotion r);
	/** The gyro-aided KLT (nothing on a depth-only frame). */
	void track(const RgbdFrame& f, const ImuPrediction& imu,
	           const cv::Mat* mask, FrameEgomotion& r);
	/** The tracks with depth in range as 3D correspondences; \a corrTrack
	 * gets each one's track index. */
	std::vector<Correspondence> correspondences(
	    const RgbdFrame& f, FrameEgomotion& r,
	    std::vector<int>& corrTrack) const;
	/** The frame-to-frame motion: IMU rotation + robust translation, or
	 * vision SE(3); the best guess when it fails. */
	FrameToFrame estimate(const RgbdFrame& f, const ImuPrediction& imu,
	                      FrameEgomotion& r);
	/** The frame's attitude R_WC from the IMU: the gyro's rotation since
	 * the previous frame pulled towards the filter's attitude by
	 * attitude_blend (not while it converges, unless
	 * follow_converging_attitude), or the filter's as is. */
	Eigen::Matrix3d imuAttitude(const ImuPrediction& imu,
	                            bool converging) const;
	/** The translation of the correspondences given the IMU's rotation
	 * R_rel, refined as [translation] says. */
	MotionEstimate translationGivenRotation(
	    const std::vector<Correspondence>& corr, const Eigen::Matrix3d& R_rel,
	    const Eigen::Matrix3d& K, FrameEgomotion& r);
	/** The pose that motion predicts (the IMU's attitude while the filter
	 * converges; the world turned to the IMU's first attitude). */
	void predictPose(const ImuPrediction& imu, const FrameToFrame& m,
	                 FrameEgomotion& r);
	/** The inertial prediction of the frame's position ([inertial]): the
	 * alignment's translation prior, and the frame-to-frame position it
	 * replaces as the prediction (the alignment's second guess). */
	struct InertialPrediction
	{
		TranslationPrior prior;  ///< t_WC and the information for the fit
		Eigen::Vector3d t_frameToFrame;
	};
	/** Propagates the filter to the frame (nullopt when it is off): the
	 * prediction becomes the frame's position. */
	std::optional<InertialPrediction> predictInertial(const RgbdFrame& f,
	                                                  FrameEgomotion& r);
	/** The pose measured against the static scene's keyframes ([anchor]):
	 * when accepted it replaces the prediction and \a m's motion; with the
	 * inertial prediction \a in as the translation's prior and gate, and
	 * the filter updated with the accepted alignment. */
	void anchorToKeyframes(const RgbdFrame& f, const cv::Mat* mask,
	                       const InertialPrediction* in, FrameToFrame& m,
	                       FrameEgomotion& r);
	/** The previous frame's mask moved to where its movers are expected in
	 * this frame (empty: none, or too large: kFlagMaskIgnored); \a excluded
	 * gets its share of the image. */
	cv::Mat expectedMovers(const RgbdFrame& f, const cv::Mat* mask,
	                       FrameEgomotion& r, double& excluded) const;
	/** An accepted alignment: the pose, the filter's update, \a m's
	 * motion. */
	void takeAnchor(const InertialPrediction* in, FrameToFrame& m,
	                FrameEgomotion& r);
	/** An alignment tried and refused: the flags, the degeneracy; whether
	 * the anchor is lost (lost_frames in a row). */
	bool missedAnchor(const InertialPrediction* in, FrameEgomotion& r);
	/** Whether the depth-inertial filter runs ([inertial] enable, mode imu
	 * with R_IC). */
	bool inertialOn() const;
	/** The frame becomes the next one's previous. */
	void commit(const RgbdFrame& f, const ImuPrediction& imu,
	            const FrameToFrame& m, FrameEgomotion& r);

	/** Whether \a moving covers more than [anchor] max_excluded_fraction of
	 * the image: then it is not used (the one rule for the previous
	 * frame's mask and its prediction). \param share gets the share. */
	bool tooLarge(const cv::Mat& moving, double* share = nullptr) const;

	EgoConfig cfg_;
	AttitudeFilter att_;
	GyroAidedKLT klt_;
	TranslationEstimator est_;
	KeyframeAnchor anchor_;
	InertialFilter inertial_;
	int anchorFailures_ = 0;  // frames in a row without an accepted anchor
	bool lastAnchored_ = false;
	bool havePrev_ = false;
	double tPrev_ = 0;
	cv::Mat depthPrev_;
	std::optional<Eigen::Matrix3d> R_WC_imuPrev_, R_WC_gyroPrev_;
	mrpt::poses::CPose3D T_WC_;  // latest pose
	Eigen::Matrix3d R_WC_ = Eigen::Matrix3d::Identity();
	Eigen::Vector3d t_WC_ = Eigen::Vector3d::Zero();
	// pose of the previous frame, for correctLastMotion()
	Eigen::Matrix3d R_WCprev_ = Eigen::Matrix3d::Identity();
	Eigen::Vector3d t_WCprev_ = Eigen::Vector3d::Zero();
	bool haveMotion_ = false;
	Eigen::Matrix3d lastR_rel_ = Eigen::Matrix3d::Identity();
	Eigen::Vector3d lastT_rel_ = Eigen::Vector3d::Zero();
	size_t nFrames_ = 0;
};

/** Eigen rotation + translation -> CPose3D. */
mrpt::poses::CPose3D toPose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

}  // namespace bims::ego
