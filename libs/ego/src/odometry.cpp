#include <bims/common/clock.h>
#include <bims/common/so3.h>
#include <bims/ego/flags.h>
#include <bims/ego/moving_prediction.h>
#include <bims/ego/odometry.h>

#include <mrpt/math/CMatrixFixed.h>

#include <opencv2/imgproc.hpp>

#include <chrono>
#include <stdexcept>

namespace bims::ego
{
const char* toString(RotationSource s)
{
	switch (s)
	{
		case RotationSource::Imu:
			return "imu";
		case RotationSource::ImuRefined:
			return "imu_refined";
		case RotationSource::Vision:
			return "vision";
		default:
			return "none";
	}
}

bool FrameEgomotion::registered() const
{
	if (flags & kFlagFirstFrame) return true;
	if (!ok()) return false;
	return !(flags & kFlagInertialRejected) || (flags & kFlagAnchored);
}

bool FrameEgomotion::ok() const
{
	if (flags & (kFlagOutOfOrder | kFlagBadImage)) return false;
	// without an image only the keyframe alignment measures the motion
	if (flags & kFlagNoImage) return (flags & kFlagAnchored) != 0;
	// the keyframe alignment measures the motion even without tracks
	return (flags & kFlagAnchored) ||
	       !(flags & (kFlagTooFewTracks | kFlagTooFewInliers));
}

mrpt::poses::CPose3D toPose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t)
{
	mrpt::math::CMatrixDouble33 Rm;
	mrpt::math::CVectorFixedDouble<3> tv;
	for (int i = 0; i < 3; i++)
	{
		tv[i] = t[i];
		for (int j = 0; j < 3; j++) Rm(i, j) = R(i, j);
	}
	return mrpt::poses::CPose3D::FromRotationAndTranslation(Rm, tv);
}

Odometry::Odometry(const EgoConfig& cfg)
    : cfg_(cfg),
      att_(cfg.attitude),
      klt_(cfg.tracker),
      est_(cfg.translation),
      anchor_(cfg.anchor),
      inertial_(cfg.inertial)
{
}

bool Odometry::inertialOn() const
{
	return cfg_.inertial.enable && cfg_.odometry.mode == OdometryMode::Imu &&
	       cfg_.calibration.has_R_IC;
}

uint32_t Odometry::addImu(const mrpt::obs::CObservationIMU& obs)
{
	if (!cfg_.sensors.imu_label.empty() &&
	    obs.sensorLabel != cfg_.sensors.imu_label)
		return 0;
	return addImu(imuSampleFrom(obs));
}

uint32_t Odometry::addImu(const ImuSample& s)
{
	if (s.hasAcc && inertialOn()) inertial_.addAccel(s.t, s.acc);
	return att_.add(s);
}

std::optional<Eigen::Matrix3d> Odometry::imuRotation(double tCam,
                                                     uint32_t* flags,
                                                     bool gyroOnly) const
{
	if (!cfg_.calibration.has_R_IC)
	{
		if (flags) *flags |= kFlagImuMissing;
		return std::nullopt;
	}
	const double t = tCam + cfg_.calibration.time_offset_s;
	const auto q =
	    gyroOnly ? att_.gyroAttitudeAt(t, flags) : att_.attitudeAt(t, flags);
	if (!q) return std::nullopt;
	return Eigen::Matrix3d(q->toRotationMatrix() * cfg_.calibration.R_IC);
}

Eigen::Matrix3d Odometry::predictRotation(double tCam) const
{
	if (!havePrev_) return Eigen::Matrix3d::Identity();
	if (R_WC_gyroPrev_)
		if (const auto R = imuRotation(tCam, nullptr, true))
			return R_WC_gyroPrev_->transpose() * *R;
	return lastR_rel_;
}

FrameEgomotion Odometry::processFrame(
    const mrpt::obs::CObservation3DRangeScan& obs, const cv::Mat* mask)
{
	const auto t0 = std::chrono::steady_clock::now();
	RgbdFrame f;
	const std::string err = rgbdFrameFrom(obs, cfg_.camera, f);
	if (!err.empty())
	{
		FrameEgomotion r;
		r.t = f.t;
		r.T_WC = T_WC_;
		r.flags = kFlagBadImage;
		haveMotion_ = false;
		return r;
	}
	const double msIn = msSince(t0);
	FrameEgomotion r = processFrame(f, mask);
	r.ms_input = msIn;
	return r;
}

// One frame in named steps: the previous frame's moving mask (guarded,
// vetoed by the geometry), the IMU's prediction, the tracker, the
// frame-to-frame estimate, the pose it predicts, the alignment to the static
// scene's keyframes, and the commit of the frame as the next one's previous.
FrameEgomotion Odometry::processFrame(const RgbdFrame& f, const cv::Mat* mask)
{
	FrameEgomotion r;
	r.t = f.t;
	haveMotion_ = false;
	if (havePrev_ && !(f.t > tPrev_))
	{
		r.T_WC = T_WC_;
		r.flags = kFlagOutOfOrder;
		return r;
	}
	++nFrames_;
	lastAnchored_ = false;
	const cv::Mat moving = takeMovingMask(mask, r);
	mask = moving.empty() ? nullptr : &moving;
	const ImuPrediction imu = predictFromImu(f.t);
	if (!havePrev_) return firstFrame(f, imu, mask, r);
	track(f, imu, mask, r);
	const auto t2 = std::chrono::steady_clock::now();
	FrameToFrame m = estimate(f, imu, r);
	predictPose(imu, m, r);
	const std::optional<InertialPrediction> in = predictInertial(f, r);
	if (in) m.t_rel = R_WCprev_.transpose() * (t_WC_ - t_WCprev_);
	if (cfg_.anchor.enable)
		anchorToKeyframes(f, mask, in ? &*in : nullptr, m, r);
	r.ms_motion = msSince(t2);
	commit(f, imu, m, r);
	return r;
}

cv::Mat Odometry::takeMovingMask(const cv::Mat* mask, FrameEgomotion& r)
{
	const bool anchoring = cfg_.anchor.enable;
	// What moved in the previous frame: the caller's mask (segmentation;
	// none before a previous frame). Not used when it covers too much of
	// the image. (The anchor's own outliers are not fed back:
	// that locked a pose onto a mover and cost 2-3x the ATE on the crowded
	// preset and Bonn; docs/ego.md.)
	cv::Mat moving;
	if (havePrev_ && mask && !mask->empty())
	{
		if (mask->type() != CV_8UC1 || mask->size() != depthPrev_.size())
			throw std::invalid_argument(
			    "Odometry: the moving mask must be CV_8UC1 of the previous "
			    "frame's size");
		moving = *mask;
		if (tooLarge(moving))
		{
			r.flags |= kFlagMaskIgnored;
			moving.release();
		}
	}
	// The geometry's veto: the regions of the mask that the previous
	// frame's alignment found on the static keyframe are not left out (a
	// tier's false alarm must not cost the tracker the static scene).
	if (anchoring && !moving.empty())
	{
		double vetoed = 0;
		moving = anchor_.vetoMask(moving, &vetoed);
		if (vetoed > 0) r.flags |= kFlagMaskVetoed;
		r.mask_vetoed = vetoed;
	}
	// The previous frame becomes a keyframe now that its moving mask is
	// known (the same mask, after the same guard).
	if (anchoring && anchor_.addPending(moving)) r.flags |= kFlagNewKeyframe;
	return moving;
}

Odometry::ImuPrediction Odometry::predictFromImu(double t) const
{
	ImuPrediction p;
	p.R_WC = imuRotation(t, &p.flags);
	p.R_WC_gyro = imuRotation(t, nullptr, true);
	if (p.R_WC_gyro && R_WC_gyroPrev_)
		p.R_rel_gyro = R_WC_gyroPrev_->transpose() * *p.R_WC_gyro;
	return p;
}

FrameEgomotion Odometry::firstFrame(const RgbdFrame& f,
                                    const ImuPrediction& imu,
                                    const cv::Mat* mask, FrameEgomotion r)
{
	// The reference: the IMU attitude when there is one.
	if (imu.R_WC)
	{
		R_WC_ = *imu.R_WC;
		r.R_source = RotationSource::Imu;
	}
	T_WC_ = toPose(R_WC_, t_WC_);
	if (inertialOn())
		inertial_.initialize(f.t + cfg_.calibration.time_offset_s, t_WC_);
	const auto t1 = std::chrono::steady_clock::now();
	if (f.hasImage())
		klt_.track(f.grey, f.K, nullptr, mask);
	else
		klt_.reset();
	r.ms_track = msSince(t1);
	if (cfg_.anchor.enable)
	{
		r.anchor = anchor_.track(f, R_WC_, t_WC_, {}, nullptr, cv::Mat());
		anchor_.wantKeyframe(r.anchor, R_WC_, t_WC_, true);
		r.ms_anchor = r.anchor.ms;
	}
	r.T_WC = T_WC_;
	const bool imuMode = cfg_.odometry.mode == OdometryMode::Imu;
	r.flags = kFlagFirstFrame | (imuMode ? imu.flags : 0) |
	          (f.hasImage() ? 0u : uint32_t(kFlagNoImage));
	havePrev_ = true;
	tPrev_ = f.t;
	depthPrev_ = f.depth.clone();
	R_WC_imuPrev_ = imu.R_WC;
	R_WC_gyroPrev_ = imu.R_WC_gyro;
	return r;
}

void Odometry::track(const RgbdFrame& f, const ImuPrediction& imu,
                     const cv::Mat* mask, FrameEgomotion& r)
{
	// Rotation prediction for the tracker.
	std::optional<Eigen::Matrix3d> R_pred;
	if (cfg_.odometry.gyro_aid)
	{
		if (imu.R_rel_gyro)
			R_pred = imu.R_rel_gyro;
		else
		{
			R_pred = lastR_rel_;  // constant angular velocity
			r.flags |= kFlagConstVelPrediction;
		}
	}
	const auto t1 = std::chrono::steady_clock::now();
	// A depth-only frame has no features: its motion is the IMU's rotation
	// (else constant velocity) and the last translation, then measured by
	// the keyframe alignment alone (geometric term). The tracker starts
	// afresh at the next frame with an image.
	if (f.hasImage())
	{
		r.tracks = klt_.track(f.grey, f.K, R_pred ? &*R_pred : nullptr, mask);
		r.tracker = klt_.stats();
		r.attempted = klt_.attemptedPoints();
	}
	else
	{
		klt_.reset();
		r.flags |= kFlagNoImage;
	}
	r.ms_track = msSince(t1);
}

std::vector<Correspondence> Odometry::correspondences(
    const RgbdFrame& f, FrameEgomotion& r, std::vector<int>& corrTrack) const
{
	std::vector<Correspondence> corr;
	r.trackInlier.assign(r.tracks.size(), -1);
	const double zmin = cfg_.translation.min_depth_m,
	             zmax = cfg_.translation.max_depth_m;
	for (size_t i = 0; i < r.tracks.size(); i++)
	{
		const float z0 = depthAt(depthPrev_, r.tracks[i].prev);
		const float z1 = depthAt(f.depth, r.tracks[i].cur);
		if (z0 < zmin || z0 > zmax || z1 < zmin || z1 > zmax) continue;
		Correspondence c;
		c.p_prev = backProject(f.K, r.tracks[i].prev, z0);
		c.p_cur = backProject(f.K, r.tracks[i].cur, z1);
		c.x_prev = {r.tracks[i].prev.x, r.tracks[i].prev.y};
		c.x_cur = {r.tracks[i].cur.x, r.tracks[i].cur.y};
		corr.push_back(c);
		corrTrack.push_back(static_cast<int>(i));
	}
	r.correspondences = static_cast<int>(corr.size());
	return corr;
}

Odometry::FrameToFrame Odometry::estimate(const RgbdFrame& f,
                                          const ImuPrediction& imu,
                                          FrameEgomotion& r)
{
	std::vector<int> corrTrack;
	const std::vector<Correspondence> corr = correspondences(f, r, corrTrack);
	const bool image = f.hasImage();
	const bool imuMode = cfg_.odometry.mode == OdometryMode::Imu;
	FrameToFrame out;
	// The IMU gives the inter-frame rotation only with a gyro chain over
	// the interval or an IMU attitude at the previous frame: otherwise
	// (e.g. the IMU starts after the first frame) R_WC_^T R_WC_imu would be
	// the jump from the unanchored start to the filter's attitude, not a
	// motion. Such a frame takes the vision estimate.
	out.reanchorWorld = imuMode && imu.R_WC.has_value() &&
	                    !imu.R_rel_gyro.has_value() &&
	                    !R_WC_imuPrev_.has_value();
	out.useImu = imuMode && imu.R_WC.has_value() && !out.reanchorWorld;
	out.filterConverging =
	    att_.converging(f.t + cfg_.calibration.time_offset_s);
	Eigen::Matrix3d R_imuRel = Eigen::Matrix3d::Identity();
	if (imuMode) r.flags |= imu.flags;
	MotionEstimate m;
	if (out.useImu)
	{
		R_imuRel = R_WC_.transpose() * imuAttitude(imu, out.filterConverging);
		r.R_source = RotationSource::Imu;
		if (image) m = translationGivenRotation(corr, R_imuRel, f.K, r);
	}
	else if (image)
	{
		m = est_.estimateSE3(corr);
		if (m.ok && cfg_.translation.reprojection)
			m = est_.refineReprojection(corr, m, f.K, true);
		r.R_source = RotationSource::Vision;
	}
	// (a frame without an image has no features to count: kFlagNoImage
	// says why)
	if (image && r.correspondences < cfg_.odometry.min_tracks)
		r.flags |= kFlagTooFewTracks;
	else if (image && !m.ok)
		r.flags |= kFlagTooFewInliers;

	if (image && !(r.flags & (kFlagTooFewTracks | kFlagTooFewInliers)))
	{
		out.R_rel = m.R_CprevC;
		out.t_rel = m.t_CprevC;
		r.inliers = m.inliers;
		r.residual_rms_m = m.residual_rms_m;
		for (size_t k = 0; k < corrTrack.size(); k++)
			r.trackInlier[corrTrack[k]] = m.inlier.empty() ? 0 : m.inlier[k];
	}
	else
	{
		// Failure: keep going with the best guess (IMU rotation if any,
		// else constant velocity); the flags say the motion is not measured.
		out.R_rel = out.useImu ? R_imuRel : lastR_rel_;
		out.t_rel = lastT_rel_;
		r.R_source = out.useImu ? RotationSource::Imu : RotationSource::None;
	}
	out.R_rel = orthonormalize(out.R_rel);
	return out;
}

Eigen::Matrix3d Odometry::imuAttitude(const ImuPrediction& imu,
                                      bool converging) const
{
	// Relative prior anchored on the absolute IMU attitude, so that the
	// estimated R_WC never drifts from the filter's.
	// Inter-frame rotation from the gyro; the absolute attitude pulled
	// towards the filter's by attitude_blend per frame (no drift, and
	// no correction noise in the inter-frame rotations).
	if (!imu.R_rel_gyro) return *imu.R_WC;
	const Eigen::Matrix3d R_pred = R_WC_ * *imu.R_rel_gyro;
	const double blend = converging && !cfg_.odometry.follow_converging_attitude
	                         ? 0.0
	                         : cfg_.odometry.attitude_blend;
	return R_pred * expSO3(blend * logSO3(R_pred.transpose() * *imu.R_WC));
}

MotionEstimate Odometry::translationGivenRotation(
    const std::vector<Correspondence>& corr, const Eigen::Matrix3d& R_rel,
    const Eigen::Matrix3d& K, FrameEgomotion& r)
{
	MotionEstimate m = est_.estimateTranslation(corr, R_rel);
	if (m.ok && cfg_.translation.reprojection &&
	    cfg_.translation.refine != TranslationRefine::SE3)
		m = est_.refineReprojection(corr, m, K, false);
	if (m.ok && cfg_.translation.refine == TranslationRefine::SE3)
	{
		m = est_.refineSE3(
		    corr, m, R_rel,
		    cfg_.translation.rotation_prior_sigma_deg * M_PI / 180);
		r.R_source = RotationSource::ImuRefined;
	}
	return m;
}

void Odometry::predictPose(const ImuPrediction& imu, const FrameToFrame& m,
                           FrameEgomotion& r)
{
	R_WCprev_ = R_WC_;
	t_WCprev_ = t_WC_;
	haveMotion_ = true;
	t_WC_ += R_WC_ * m.t_rel;
	// While the attitude filter is still converging its absolute attitude
	// moves fast: follow it for the absolute R_WC, but never feed that
	// convergence into the inter-frame rotation used above.
	if (m.useImu && m.filterConverging &&
	    cfg_.odometry.follow_converging_attitude)
		R_WC_ = *imu.R_WC;
	else
		R_WC_ = orthonormalize(R_WC_ * m.R_rel);
	if (m.reanchorWorld)
	{
		// Rotate the world so that R_WC is the filter's from now on.
		const Eigen::Matrix3d R_fix = *imu.R_WC * R_WC_.transpose();
		R_WC_ = *imu.R_WC;
		t_WC_ = R_fix * t_WC_;
		R_WCprev_ = R_fix * R_WCprev_;
		t_WCprev_ = R_fix * t_WCprev_;
		r.flags |= kFlagWorldReanchored;
		anchor_.clear();  // the keyframes are in the old world
	}
}

std::optional<Odometry::InertialPrediction> Odometry::predictInertial(
    const RgbdFrame& f, FrameEgomotion& r)
{
	if (!inertialOn()) return std::nullopt;
	const double off = cfg_.calibration.time_offset_s;
	// (re)started where the world was turned to the IMU's first attitude
	if (!inertial_.initialized() || (r.flags & kFlagWorldReanchored))
		inertial_.initialize(tPrev_ + off, t_WCprev_);
	// R_WI at IMU time tau: the previous frame's, carried by the gyro chain
	// (without it, this frame's predicted rotation)
	const Eigen::Matrix3d R_CI = cfg_.calibration.R_IC.transpose();
	const Eigen::Matrix3d R_WIprev = R_WCprev_ * R_CI;
	const Eigen::Matrix3d R_WInow = R_WC_ * R_CI;
	const auto qPrev = att_.gyroAttitudeAt(tPrev_ + off);
	const auto R_WI = [&](double tau) -> std::optional<Eigen::Matrix3d>
	{
		if (qPrev)
			if (const auto q = att_.gyroAttitudeAt(tau))
				return Eigen::Matrix3d(
				    R_WIprev * (qPrev->conjugate() * *q).toRotationMatrix());
		return R_WInow;
	};
	const InertialPropagation pr = inertial_.propagate(f.t + off, R_WI);
	if (pr.prior_s > 0) r.flags |= kFlagInertialPrior;
	if (pr.saturated) r.flags |= kFlagAccelSaturated;
	InertialPrediction out;
	out.t_frameToFrame = t_WC_;
	out.prior.t = inertial_.state().p_WC;
	// the alignment weighs its data unscaled: the prior's information in
	// the same units (the filter scales the data instead)
	out.prior.info = inertial_.positionInformation() /
	                 cfg_.inertial.alignment_information_scale;
	t_WC_ = out.prior.t;
	r.inertial = true;
	return out;
}

void Odometry::anchorToKeyframes(const RgbdFrame& f, const cv::Mat* mask,
                                 const InertialPrediction* in, FrameToFrame& m,
                                 FrameEgomotion& r)
{
	// Measure the pose against the static scene, from the
	// frame-to-frame guess (and the IMU rotation as the prior).
	// The frame-to-frame estimate first; the constant-velocity
	// prediction as a second guess (features on people can corrupt the
	// first).
	// With the inertial prediction as the first guess, the frame-to-frame
	// estimate is the second.
	const InitialGuess second =
	    in ? InitialGuess{R_WC_, in->t_frameToFrame}
	       : InitialGuess{
	             m.useImu ? R_WC_ : Eigen::Matrix3d(R_WCprev_ * lastR_rel_),
	             t_WCprev_ + R_WCprev_ * lastT_rel_};
	const double infoScale = cfg_.inertial.alignment_information_scale;
	const AnchorGate gate =
	    [this, infoScale](const Eigen::Vector3d& t, const Eigen::Matrix3d& info)
	{ return inertial_.check(t, infoScale * info).accepted; };
	const Eigen::Matrix3d R_prior = R_WC_;
	double excluded = 0;
	const cv::Mat exclude = expectedMovers(f, mask, r, excluded);
	r.anchor =
	    anchor_.track(f, R_WC_, t_WC_, {second}, m.useImu ? &R_prior : nullptr,
	                  exclude, in ? &in->prior : nullptr, in ? &gate : nullptr);
	r.anchor.excluded_fraction = excluded;
	r.ms_anchor = r.anchor.ms;
	if (r.anchor.maskIgnored) r.flags |= kFlagMaskIgnored;
	bool lost = false;
	if (r.anchor.accepted)
		takeAnchor(in, m, r);
	else if (r.anchor.tried)
		lost = missedAnchor(in, r);
	if (lost)
	{
		// Go on from this frame's (frame-to-frame) pose: it becomes a
		// keyframe; the older keyframes stay for when the view returns.
		r.flags |= kFlagAnchorLost;
		anchorFailures_ = 0;
	}
	if (r.degenerate > 0) r.flags |= kFlagDegenerate;
	anchor_.wantKeyframe(r.anchor, R_WC_, t_WC_,
	                     lost || (r.flags & kFlagWorldReanchored));
}

cv::Mat Odometry::expectedMovers(const RgbdFrame& f, const cv::Mat* mask,
                                 FrameEgomotion& r, double& excluded) const
{
	// The previous frame's movers where they are expected in this one,
	// with the motion predicted as for the alignment's second guess (the
	// gyro's rotation, else the last frame's; the last translation), not
	// the frame-to-frame estimate that features on movers can corrupt.
	if (!mask) return cv::Mat();
	cv::Mat exclude =
	    cfg_.anchor.predict_mask
	        ? predictMovingMask(*mask, depthPrev_, f.K, predictRotation(f.t),
	                            lastT_rel_, cfg_.anchor.mask_margin_px)
	        : *mask;
	if (tooLarge(exclude, &excluded))
	{
		r.flags |= kFlagMaskIgnored;
		exclude.release();
	}
	return exclude;
}

void Odometry::takeAnchor(const InertialPrediction* in, FrameToFrame& m,
                          FrameEgomotion& r)
{
	R_WC_ = orthonormalize(r.anchor.R_WC);
	t_WC_ = r.anchor.t_WC;
	if (in)
	{
		// the position the filter keeps: the alignment's where it
		// measured, the prediction along what it left unconstrained
		const InertialUpdate u =
		    inertial_.update(t_WC_, cfg_.inertial.alignment_information_scale *
		                                r.anchor.position_information);
		r.degenerate = u.degeneracy.count;
		r.inertial_nis = u.nis;
		r.position_information = u.degeneracy.eigenvalues;
		t_WC_ = inertial_.state().p_WC;
	}
	m.R_rel = R_WCprev_.transpose() * R_WC_;
	m.t_rel = R_WCprev_.transpose() * (t_WC_ - t_WCprev_);
	r.flags |= kFlagAnchored;
	if (r.anchor.relocalised) r.flags |= kFlagAnchorRelocalised;
	anchorFailures_ = 0;
	lastAnchored_ = true;
}

bool Odometry::missedAnchor(const InertialPrediction* in, FrameEgomotion& r)
{
	r.flags |= kFlagAnchorFailed;
	if (r.anchor.gated) r.flags |= kFlagInertialRejected;
	if (in)
	{
		const Degeneracy d = analyseDegeneracy(
		    cfg_.inertial.alignment_information_scale *
		        r.anchor.position_information,
		    cfg_.inertial.degenerate_sigma_m, cfg_.inertial.degenerate_ratio);
		r.degenerate = d.count;
		r.position_information = d.eigenvalues;
	}
	return ++anchorFailures_ >= cfg_.anchor.lost_frames;
}

void Odometry::commit(const RgbdFrame& f, const ImuPrediction& imu,
                      const FrameToFrame& m, FrameEgomotion& r)
{
	lastR_rel_ = m.R_rel;
	lastT_rel_ = m.t_rel;
	T_WC_ = toPose(R_WC_, t_WC_);
	r.T_WC = T_WC_;
	r.T_CprevC = toPose(m.R_rel, m.t_rel);
	if (r.inertial)
	{
		r.v_W = inertial_.state().v_W;
		r.acc_bias = inertial_.state().b_a;
		r.gravity_W = inertial_.state().g_W;
	}
	tPrev_ = f.t;
	depthPrev_ = f.depth.clone();
	R_WC_imuPrev_ = imu.R_WC;
	R_WC_gyroPrev_ = imu.R_WC_gyro;
}

bool Odometry::tooLarge(const cv::Mat& moving, double* share) const
{
	const double s = cv::countNonZero(moving) / double(moving.total());
	if (share) *share = s;
	return s > cfg_.anchor.max_excluded_fraction;
}

mrpt::poses::CPose3D Odometry::correctLastMotion(
    const mrpt::poses::CPose3D& T_CprevC)
{
	if (!haveMotion_ || lastAnchored_) return T_WC_;
	Eigen::Matrix3d R;
	const auto& Rm = T_CprevC.getRotationMatrix();
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) R(i, j) = Rm(i, j);
	R = orthonormalize(R);
	const Eigen::Vector3d t(T_CprevC.x(), T_CprevC.y(), T_CprevC.z());
	t_WC_ = t_WCprev_ + R_WCprev_ * t;
	// Also while the attitude filter converges (processFrame then follows
	// the filter's absolute attitude): the corrected motion is the better
	// inter-frame rotation, and the attitude blend pulls R_WC towards the
	// filter's afterwards.
	R_WC_ = orthonormalize(R_WCprev_ * R);
	lastR_rel_ = R;
	lastT_rel_ = t;
	T_WC_ = toPose(R_WC_, t_WC_);
	// the filter's position follows (its uncertainty stays)
	if (inertialOn() && inertial_.initialized())
		inertial_.resetPosition(t_WC_, 0);
	return T_WC_;
}

}  // namespace bims::ego
