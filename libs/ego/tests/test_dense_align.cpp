// Dense alignment and map-anchored tracking on exact synthetic frames; the
// alignment's Jacobians against central differences.
#include <bims/ego/dense_align.h>
#include <bims/ego/flags.h>
#include <bims/ego/keyframe_anchor.h>
#include <bims/ego/normal_equations.h>
#include <bims/ego/odometry.h>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "synth_scene.h"

using namespace bims;  // so3.h
using namespace bims::ego;

namespace
{
using test::K320;

AnchorParams params320()
{
	AnchorParams p;
	p.finest_level = 0;  // 320 x 240: align at full size
	p.coarsest_level = 2;
	p.min_inliers = 200;
	return p;
}

/** Pastes a fronto-parallel textured board at depth z over the columns
 * [u0, u1) of the frame: an object the other frame does not hold. */
void occlude(RgbdFrame& f, int u0, int u1, float z, uint32_t seed)
{
	for (int v = 0; v < f.depth.rows; v++)
		for (int u = u0; u < u1; u++)
		{
			f.depth.at<float>(v, u) = z;
			f.grey.at<uint8_t>(v, u) = static_cast<uint8_t>(
			    test::valueNoise(u * 0.004, v * 0.004, seed));
		}
}

struct Err
{
	double t_m, R_deg;
};

Err errorOf(const DenseAlignResult& a, const Eigen::Matrix3d& R,
            const Eigen::Vector3d& t)
{
	return {(a.t_RC - t).norm(), angleSO3(a.R_RC.transpose() * R) * 180 / M_PI};
}

/** Keyframe at time 0, current frame at time tc of test::Motion. */
struct Pair
{
	RgbdFrame ref, cur;
	Eigen::Matrix3d R_RC;
	Eigen::Vector3d t_RC;
};

Pair pairAt(double tc)
{
	test::Motion m;
	Pair p;
	p.ref = test::render(m.R(0), m.p(0), K320(), 320, 240, 0);
	p.cur = test::render(m.R(tc), m.p(tc), K320(), 320, 240, tc);
	p.R_RC = m.R(0).transpose() * m.R(tc);
	p.t_RC = m.R(0).transpose() * (m.p(tc) - m.p(0));
	return p;
}
}  // namespace

TEST(DenseAlign, RecoversAKnownMotionFromAnOffGuess)
{
	const Pair s = pairAt(0.2);  // 7 cm and 4.8 deg apart
	const AnchorParams p = params320();
	DenseFrame ref, cur;
	ref.build(s.ref.grey, s.ref.depth, K320(), p);
	ref.prepareReference(p);
	cur.build(s.cur.grey, s.cur.depth, K320(), p);
	// start 2.5 cm and 1.2 deg off (a frame-to-frame guess gone wrong)
	const Eigen::Matrix3d R0 =
	    s.R_RC * expSO3(Eigen::Vector3d(0.015, -0.012, 0.008));
	const Eigen::Vector3d t0 = s.t_RC + Eigen::Vector3d(0.015, 0.01, -0.017);
	const DenseAlignResult a = alignDense(ref, cur, R0, t0, p);
	ASSERT_TRUE(a.ok) << a.why;
	const Err e = errorOf(a, s.R_RC, s.t_RC);
	EXPECT_LT(e.t_m, 0.002);
	EXPECT_LT(e.R_deg, 0.05);
	EXPECT_GT(a.inlier_fraction, 0.95);
}

TEST(DenseAlign, AnObjectOverHalfTheImageDoesNotPullThePose)
{
	const Pair s = pairAt(0.1);
	AnchorParams p = params320();
	// 55 % of the current image is a board 1.2 m away that the reference
	// does not hold (a person walking in front of the camera)
	RgbdFrame cur = s.cur;
	occlude(cur, 0, 176, 1.2f, 77);
	DenseFrame ref, dc;
	ref.build(s.ref.grey, s.ref.depth, K320(), p);
	ref.prepareReference(p);
	dc.build(cur.grey, cur.depth, K320(), p);
	const Eigen::Matrix3d R0 = s.R_RC * expSO3(Eigen::Vector3d(0.01, -0.01, 0));
	const Eigen::Vector3d t0 = s.t_RC + Eigen::Vector3d(0.02, -0.01, 0.02);
	const DenseAlignResult a = alignDense(ref, dc, R0, t0, p);
	ASSERT_TRUE(a.ok) << a.why;
	const Err e = errorOf(a, s.R_RC, s.t_RC);
	EXPECT_LT(e.t_m, 0.003);
	EXPECT_LT(e.R_deg, 0.1);
	// the board's points are the outliers
	const double boardOut =
	    cv::countNonZero(a.outliers(cv::Rect(0, 0, 170, 240))) / (170.0 * 240);
	const double restOut =
	    cv::countNonZero(a.outliers(cv::Rect(182, 0, 138, 240))) /
	    (138.0 * 240);
	EXPECT_GT(boardOut, 0.8);
	EXPECT_LT(restOut, 0.05);
	// A plain least-squares fit (no gate, no robust loss) is pulled away:
	// the test has teeth.
	AnchorParams naive = p;
	naive.gate_m = 100;
	naive.tukey_c = 1e4 / 0.004;
	naive.photo_weight = 0;
	const DenseAlignResult b = alignDense(ref, dc, R0, t0, naive);
	EXPECT_GT(errorOf(b, s.R_RC, s.t_RC).t_m, 0.01);
}

TEST(DenseAlign, NoDepthIsAFailureNotACrash)
{
	const Pair s = pairAt(0.1);
	const AnchorParams p = params320();
	DenseFrame ref, cur;
	ref.build(s.ref.grey, s.ref.depth, K320(), p);
	ref.prepareReference(p);
	cv::Mat empty = cv::Mat::zeros(s.cur.depth.size(), CV_32FC1);
	cur.build(s.cur.grey, empty, K320(), p);
	const DenseAlignResult a = alignDense(ref, cur, Eigen::Matrix3d::Identity(),
	                                      Eigen::Vector3d::Zero(), p);
	EXPECT_FALSE(a.ok);
	EXPECT_FALSE(a.why.empty());
	EXPECT_TRUE(a.R_RC.allFinite());
	// an unprepared reference is refused
	DenseFrame raw;
	raw.build(s.ref.grey, s.ref.depth, K320(), p);
	EXPECT_FALSE(alignDense(raw, cur, Eigen::Matrix3d::Identity(),
	                        Eigen::Vector3d::Zero(), p)
	                 .ok);
}

namespace
{
/** Runs Odometry over n frames of test::Motion at 20 Hz, with a board over
 * the left 55 % of every frame from frame 5 on (a different texture in each
 * frame, as a person walking), and returns the final position error [m]. */
double driftWithABoard(bool anchor, int n, int* anchored = nullptr)
{
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Vision;
	cfg.anchor = params320();
	cfg.anchor.enable = anchor;
	Odometry odo(cfg);
	test::Motion m;
	m.w_C = Eigen::Vector3d(0.05, 0.2, 0.02);
	m.v_W = Eigen::Vector3d(0.15, 0.1, 0.0);
	FrameEgomotion e;
	if (anchored) *anchored = 0;
	for (int k = 0; k < n; k++)
	{
		const double t = k * 0.05;
		RgbdFrame f = test::render(m.R(t), m.p(t), K320(), 320, 240, t);
		if (k >= 5) occlude(f, 0, 176, 1.0f + 0.01f * k, 100 + k);
		e = odo.processFrame(f);
		if (anchored && (e.flags & kFlagAnchored)) ++*anchored;
	}
	const double t = (n - 1) * 0.05;
	const Eigen::Vector3d p_true =
	    m.R(0).transpose() * (m.p(t) - m.p(0));  // in the first camera
	return (Eigen::Vector3d(e.T_WC.x(), e.T_WC.y(), e.T_WC.z()) - p_true)
	    .norm();
}
}  // namespace

TEST(KeyframeAnchor, TrackingAgainstTheKeyframeHoldsWhenABoardDominates)
{
	int anchored = 0;
	const double withAnchor = driftWithABoard(true, 30, &anchored);
	// 27 cm travelled; measured 1.4 cm
	EXPECT_GE(anchored, 25);
	EXPECT_LT(withAnchor, 0.03);
	// frame to frame, the board pulls the pose away (measured 16 cm)
	EXPECT_GT(driftWithABoard(false, 30), 0.08);
}

TEST(KeyframeAnchor, LostTrackingIsFlaggedAndRecovers)
{
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Vision;
	cfg.anchor = params320();
	cfg.anchor.lost_frames = 3;
	Odometry odo(cfg);
	test::Motion m;
	int lost = 0, failed = 0;
	FrameEgomotion e;
	for (int k = 0; k < 16; k++)
	{
		const double t = k * 0.05;
		RgbdFrame f = test::render(m.R(t), m.p(t), K320(), 320, 240, t);
		if (k >= 4 && k < 9) f.depth.setTo(0);  // a hand over the lens
		e = odo.processFrame(f);
		EXPECT_TRUE(e.T_WC.translation().norm() < 10) << k;
		if (e.flags & kFlagAnchorLost) ++lost;
		if (e.flags & kFlagAnchorFailed) ++failed;
	}
	EXPECT_GE(failed, 3);
	EXPECT_GE(lost, 1);
	// tracking resumed: the last frames are anchored again
	EXPECT_TRUE(e.flags & kFlagAnchored) << flagsToString(e.flags);
}

TEST(KeyframeAnchor, AnImuThatStopsIsFlaggedAndTheAnchorCarriesOn)
{
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Imu;
	cfg.calibration.has_R_IC = true;
	cfg.calibration.R_IC = expSO3(Eigen::Vector3d(0.3, -0.2, 0.1));
	cfg.anchor = params320();
	Odometry odo(cfg);
	test::Motion m;
	m.w_C = Eigen::Vector3d(0.05, 0.2, 0.02);
	m.v_W = Eigen::Vector3d(0.15, 0.1, 0.0);
	double tImu = 0;
	FrameEgomotion e;
	int missing = 0, anchored = 0;
	for (int k = 0; k < 16; k++)
	{
		const double t = k * 0.05;
		// the IMU stops after 0.3 s
		for (; tImu <= std::min(t + 0.03, 0.3); tImu += 0.005)
			odo.addImu(test::imuAt(m, cfg.calibration.R_IC, tImu));
		e = odo.processFrame(test::render(m.R(t), m.p(t), K320(), 320, 240, t));
		if (e.flags & (kFlagImuMissing | kFlagImuGap)) ++missing;
		if (e.flags & kFlagAnchored) ++anchored;
		ASSERT_TRUE(std::isfinite(e.T_WC.x())) << k;
	}
	EXPECT_GE(missing, 8);
	EXPECT_GE(anchored, 14);
	// the distance from the first frame (the world's origin) is still right
	const double t = 15 * 0.05;
	EXPECT_LT(std::abs((m.p(t) - m.p(0)).norm() - e.T_WC.translation().norm()),
	          0.02);
}

TEST(KeyframeAnchor, AMaskOverMostOfTheImageIsCountedAndNotUsed)
{
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Vision;
	cfg.anchor = params320();
	// (the size guard alone: the geometry's veto would take the static
	// region out of the mask; OdometryUsesTheVetoedMask)
	cfg.anchor.mask_veto_consistent = 0;
	Odometry odo(cfg);
	test::Motion m;
	cv::Mat most = cv::Mat::zeros(240, 320, CV_8UC1), some = most.clone();
	most(cv::Rect(0, 0, 300, 240)).setTo(255);  // 94 % of the image
	some(cv::Rect(0, 0, 96, 240)).setTo(255);   // 30 %
	odo.processFrame(test::render(m.R(0), m.p(0), K320(), 320, 240, 0));
	const FrameEgomotion a = odo.processFrame(
	    test::render(m.R(0.05), m.p(0.05), K320(), 320, 240, 0.05), &most);
	EXPECT_TRUE(a.flags & kFlagMaskIgnored) << flagsToString(a.flags);
	EXPECT_TRUE(a.flags & kFlagAnchored) << flagsToString(a.flags);
	EXPECT_GT(a.tracks.size(), 50u);  // the tracker was not starved
	// ... nor for the keyframe the previous frame became (it would have
	// lost 94 % of its readings)
	EXPECT_LT(cv::countNonZero(a.anchor.outliers),
	          0.1 * a.anchor.outliers.total());
	const FrameEgomotion b = odo.processFrame(
	    test::render(m.R(0.1), m.p(0.1), K320(), 320, 240, 0.1), &some);
	EXPECT_FALSE(b.flags & kFlagMaskIgnored) << flagsToString(b.flags);
	EXPECT_TRUE(b.flags & kFlagAnchored);
	EXPECT_GT(b.anchor.excluded_fraction, 0.2);  // the mask was used
}

namespace
{
/** test::Motion seen by a KeyframeAnchor: frames and true poses in the
 * first camera's frame; construction makes frame 0 keyframe 0 (without
 * readings in \a unseen: space it never saw). */
struct AnchorOnMotion
{
	KeyframeAnchor anchor{params320()};
	test::Motion m;
	explicit AnchorOnMotion(const cv::Rect& unseen = {})
	{
		RgbdFrame f0 = frame(0);
		f0.depth(unseen).setTo(0);
		const AnchorResult a =
		    anchor.track(f0, R(0), p(0), {}, nullptr, cv::Mat());
		anchor.wantKeyframe(a, R(0), p(0), true);
		EXPECT_TRUE(anchor.addPending(cv::Mat()));  // keyframe 0
	}
	RgbdFrame frame(double t) const
	{
		return test::render(m.R(t), m.p(t), K320(), 320, 240, t);
	}
	Eigen::Matrix3d R(double t) const { return m.R(0).transpose() * m.R(t); }
	Eigen::Vector3d p(double t) const
	{
		return m.R(0).transpose() * (m.p(t) - m.p(0));
	}
	AnchorResult track(const RgbdFrame& f, double t, const cv::Mat& mask = {})
	{
		return anchor.track(f, R(t), p(t), {}, nullptr, mask);
	}
};
}  // namespace

TEST(KeyframeAnchor, AKeyframeLeftWithLittleStaticSceneFallsBackToAnOlderOne)
{
	// Keyframe 1 is made from a frame whose moving mask covered 99 % of it
	// (a mover filling the view): it holds too little to anchor to, and it
	// is the nearest and newest one. The next frame anchors to keyframe 0.
	AnchorOnMotion s;
	AnchorResult a = s.track(s.frame(0.05), 0.05);
	EXPECT_TRUE(a.accepted) << a.why;
	s.anchor.wantKeyframe(a, s.R(0.05), s.p(0.05), true);
	cv::Mat most = cv::Mat::zeros(240, 320, CV_8UC1);
	most(cv::Rect(0, 0, 316, 240)).setTo(255);
	EXPECT_TRUE(s.anchor.addPending(most));  // keyframe 1: 1 % of its readings
	EXPECT_EQ(s.anchor.keyframes(), 2u);
	a = s.track(s.frame(0.1), 0.1);
	EXPECT_TRUE(a.accepted) << a.why;
	EXPECT_EQ(a.keyframe, 0);
}

TEST(KeyframeAnchor, AKeyframeThatMatchesLittleOfTheFrameGivesWayToAnother)
{
	// Keyframe 1 is made while a board 1 m away covers 85 % of the view; its
	// mask misses the board's edge, where keyframe 0 saw nothing (a mover
	// entering unseen space: no alignment outlier there either), so the edge
	// stays in keyframe 1. The board then retreats: the room behind it is
	// where keyframe 1 dropped the board (covered: no new keyframe), and
	// keyframe 1, the nearest, accepts the next frame on its small static
	// share (under half of the frame's points inliers). Keyframe 0 matches
	// more of that frame and anchors it. (Before: keyframe 1, and on the
	// simulator's occluder preset the pose followed the board's edge.)
	AnchorOnMotion s(cv::Rect(248, 0, 28, 240));
	const auto boardAndMask = [&s](double t, int edge)
	{
		std::pair<RgbdFrame, cv::Mat> fm{s.frame(t), cv::Mat()};
		occlude(fm.first, 0, edge, 1.0f, 3);
		fm.second = cv::Mat::zeros(240, 320, CV_8UC1);
		fm.second(cv::Rect(0, 0, edge - 16, 240)).setTo(255);  // but its edge
		return fm;
	};
	const auto [f1, mask1] = boardAndMask(0.05, 272);
	AnchorResult a = s.track(f1, 0.05, mask1);
	ASSERT_TRUE(a.accepted) << a.why;
	s.anchor.wantKeyframe(a, s.R(0.05), s.p(0.05), true);
	ASSERT_TRUE(s.anchor.addPending(mask1));  // keyframe 1
	const auto [f2, mask2] = boardAndMask(0.1, 224);
	a = s.track(f2, 0.1, mask2);
	EXPECT_TRUE(a.accepted) << a.why;
	EXPECT_EQ(a.keyframe, 0);
	EXPECT_GT(a.overlap, 0.5);
	EXPECT_LT((a.t_WC - s.p(0.1)).norm(), 0.01);
}

TEST(KeyframeAnchor, AMaskThatLeavesNothingToAlignIsRetriedWithout)
{
	// The mask covers 60 % of the frame (below max_excluded_fraction) and
	// the rest is a board the keyframe does not hold (occluders, no
	// inliers): with the mask nothing is left to align, so the alignment is
	// tried once more without it (flagged), not failed.
	AnchorOnMotion s;
	RgbdFrame f = s.frame(0.05);
	cv::Mat mask = cv::Mat::zeros(240, 320, CV_8UC1);
	mask(cv::Rect(0, 0, 192, 240)).setTo(255);  // 60 %
	occlude(f, 192, 320, 1.0f, 7);
	const AnchorResult a = s.track(f, 0.05, mask);
	EXPECT_TRUE(a.accepted) << a.why;
	EXPECT_TRUE(a.maskIgnored);
	EXPECT_LT((a.t_WC - s.p(0.05)).norm(), 0.01);
}

TEST(NormalEquations6, EqualTheSumsOfTheirResidualsAndClearEmptiesThem)
{
	// H = sum w J^T J, b = sum w J^T r, as a plain loop sums them
	std::mt19937 rng(7);
	std::uniform_real_distribution<double> u(-2, 2), uw(0, 1);
	NormalEquations6 ne;
	NormalEquations6::Mat6 H, Hn = NormalEquations6::Mat6::Zero();
	NormalEquations6::Vec6 b, bn = NormalEquations6::Vec6::Zero();
	ne.get(H, b);
	EXPECT_EQ(H.norm() + b.norm(), 0);
	for (int round = 0; round < 2; round++)
	{
		ne.clear();
		Hn.setZero();
		bn.setZero();
		for (int k = 0; k < 1000 + 37 * round; k++)
		{
			float J[6];
			for (float& j : J) j = float(u(rng));
			const double w = uw(rng), r = u(rng);
			ne.add(J, std::sqrt(w), r);
			for (int i = 0; i < 6; i++)
			{
				bn[i] += w * J[i] * r;
				for (int j = 0; j < 6; j++) Hn(i, j) += w * J[i] * J[j];
			}
		}
		EXPECT_EQ(ne.size(), size_t(1000 + 37 * round));
		ne.get(H, b);
		EXPECT_LT((H - Hn).norm(), 1e-10 * Hn.norm()) << H << "\n\n" << Hn;
		EXPECT_LT((b - bn).norm(), 1e-10 * bn.norm()) << b.transpose();
	}
}

TEST(Tukey, WeightIsTheSquareOfSAndTheLossIsFlatBeyondC)
{
	const double c = 4.685;
	for (double e : {0.0, 0.5, -1.0, 2.0, -4.0, 4.6})
	{
		const Tukey t = Tukey::at(e / c, c);
		const double q = 1 - (e / c) * (e / c);
		EXPECT_NEAR(t.s * t.s, q * q, 1e-15) << e;
		EXPECT_NEAR(t.loss, c * c / 6 * (1 - q * q * q), 1e-12) << e;
	}
	EXPECT_EQ(Tukey::at(0, c).loss, 0);
	for (double e : {4.685, -5.0, 100.0})
	{
		EXPECT_EQ(Tukey::at(e / c, c).s, 0) << e;
		EXPECT_EQ(Tukey::at(e / c, c).loss, c * c / 6) << e;
	}
}

// The geometry's veto of a fed-back mask: of two regions called moving in a
// frame, the one its alignment found on the static keyframe's surface (a
// false alarm) is left out of the mask; the one on an object in front of
// the keyframe's surface (a mover) stays. Off, the mask is kept whole.
TEST(KeyframeAnchor, TheAlignmentVetoesMaskRegionsItFoundOnTheStaticScene)
{
	AnchorOnMotion s;
	RgbdFrame f = s.frame(0.05);
	// an object 40 cm in front of the room in this frame only
	const cv::Rect object(200, 80, 60, 60), falseAlarm(40, 60, 60, 60);
	f.depth(object) -= 0.4f;
	const AnchorResult a = s.track(f, 0.05);
	ASSERT_TRUE(a.accepted) << a.why;
	cv::Mat mask = cv::Mat::zeros(240, 320, CV_8UC1);
	mask(object).setTo(255);
	mask(falseAlarm).setTo(255);
	double vetoed = -1;
	const cv::Mat kept = s.anchor.vetoMask(mask, &vetoed);
	EXPECT_EQ(cv::countNonZero(kept(falseAlarm)), 0);
	EXPECT_EQ(cv::countNonZero(kept(object)), object.area());
	EXPECT_DOUBLE_EQ(vetoed, 0.5);
	EXPECT_EQ(cv::countNonZero(mask), 2 * object.area());  // input untouched
	// a mask of another size, or the veto off: the mask as it is
	EXPECT_EQ(
	    cv::countNonZero(s.anchor.vetoMask(cv::Mat::ones(24, 32, CV_8UC1))),
	    24 * 32);
	AnchorParams off = params320();
	off.mask_veto_consistent = 0;
	KeyframeAnchor b(off);
	const AnchorResult a0 =
	    b.track(s.frame(0), s.R(0), s.p(0), {}, nullptr, cv::Mat());
	b.wantKeyframe(a0, s.R(0), s.p(0), true);
	ASSERT_TRUE(b.addPending(cv::Mat()));
	ASSERT_TRUE(
	    b.track(f, s.R(0.05), s.p(0.05), {}, nullptr, cv::Mat()).accepted);
	EXPECT_EQ(cv::countNonZero(b.vetoMask(mask)), 2 * object.area());
}

// Odometry feeds the vetoed mask on: a false alarm over the static room
// (the bottom tier's, without the flow tier's veto) from the second frame on
// (the first frame's mask is empty: a warm-up frame) is neither excluded
// from the alignment nor dropped from the keyframe; the frame says so.
// Without the veto it is excluded on every frame.
TEST(KeyframeAnchor, OdometryUsesTheVetoedMask)
{
	cv::Mat falseAlarm = cv::Mat::zeros(240, 320, CV_8UC1);
	falseAlarm(cv::Rect(20, 20, 150, 150)).setTo(255);  // 29 % of the view
	for (const bool veto : {true, false})
	{
		EgoConfig cfg;
		cfg.odometry.mode = OdometryMode::Vision;
		cfg.anchor = params320();
		if (!veto) cfg.anchor.mask_veto_consistent = 0;
		Odometry odo(cfg);
		test::Motion m;
		for (int k = 0; k < 4; k++)
		{
			const FrameEgomotion e =
			    odo.processFrame(test::render(m.R(k * 0.05), m.p(k * 0.05),
			                                  K320(), 320, 240, k * 0.05),
			                     k > 1 ? &falseAlarm : nullptr);
			SCOPED_TRACE(std::string(veto ? "veto, " : "no veto, ") + "frame " +
			             std::to_string(k) + ": " + flagsToString(e.flags));
			EXPECT_TRUE(e.flags & kFlagAnchored || k == 0);
			if (k < 2) continue;  // frame 1's mask is the first
			EXPECT_EQ((e.flags & kFlagMaskVetoed) != 0, veto);
			if (veto)
			{
				EXPECT_GT(e.mask_vetoed, 0.99);
				EXPECT_LT(e.anchor.excluded_fraction, 0.01);
			}
			else
				EXPECT_GT(e.anchor.excluded_fraction, 0.25);
		}
	}
}

namespace
{
/** A smooth grey image I(u, v) (for the photometric Jacobian: its gradient
 * is exact) and its gradient [grey/px]. */
double smoothGrey(double u, double v)
{
	return 120 + 40 * std::sin(0.05 * u + 0.3) * std::cos(0.04 * v - 0.2) +
	       0.002 * u * v;
}
Eigen::Vector2d smoothGreyGradient(double u, double v)
{
	return {0.05 * 40 * std::cos(0.05 * u + 0.3) * std::cos(0.04 * v - 0.2) +
	            0.002 * v,
	        -0.04 * 40 * std::sin(0.05 * u + 0.3) * std::sin(0.04 * v - 0.2) +
	            0.002 * u};
}

/** The current point p at the pose (R, t) after the increment d = (v, w),
 * as alignDense() applies it (R <- Exp(w) R, t <- Exp(w) t + v). */
Eigen::Vector3d movedPoint(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                           const Eigen::Vector3d& p,
                           const Eigen::Matrix<double, 6, 1>& d)
{
	const Eigen::Matrix3d dR = expSO3(d.tail<3>());
	return dR * R * p + (dR * t + d.head<3>());
}

/** Largest |analytic - numeric| over Jacobian rows, absolute and relative
 * to each row's largest numeric entry. */
struct MaxErr
{
	double abs = 0, rel = 0;
	/** Adds a row; returns its relative error. */
	template <typename T>
	double add(const T* a, const double* n)
	{
		double scale = 0, row = 0;
		for (int i = 0; i < 6; i++) scale = std::max(scale, std::abs(n[i]));
		for (int i = 0; i < 6; i++)
		{
			const double e = std::abs(double(a[i]) - n[i]);
			abs = std::max(abs, e);
			row = std::max(row, e / scale);
		}
		rel = std::max(rel, row);
		return row;
	}
};
}  // namespace

// The point-to-plane and photometric Jacobians of alignDense() against
// central differences of their residuals under the alignment's increment, at
// random poses, points, planes and image positions.
TEST(DenseAlign, JacobianMatchesCentralDifferences)
{
	std::mt19937 rng(20240611);
	std::uniform_real_distribution<double> U(-1, 1), Zd(0.5, 5);
	const Eigen::Matrix3d K = K320();
	const double fx = K(0, 0), fy = K(1, 1), cx = K(0, 2), cy = K(1, 2);
	const double h = 1e-6, tol = 1e-5;
	MaxErr geo, photo;
	MaxErr inFloat;  // float against double instantiation
	int n = 0;
	while (n < 40)
	{
		const Eigen::Matrix3d R =
		    expSO3(0.4 * Eigen::Vector3d(U(rng), U(rng), U(rng)));
		const Eigen::Vector3d t = 0.3 * Eigen::Vector3d(U(rng), U(rng), U(rng));
		const double z = Zd(rng);
		const Eigen::Vector3d p(0.6 * z * U(rng), 0.45 * z * U(rng), z);
		const Eigen::Vector3d X = R * p + t;
		if (X.z() < 0.3) continue;
		++n;
		// a plane through a point near X
		const Eigen::Vector3d nrm =
		    Eigen::Vector3d(U(rng), U(rng), U(rng) - 1.5).normalized();
		const double dpl =
		    nrm.dot(X + 0.05 * Eigen::Vector3d(U(rng), U(rng), U(rng)));
		const auto rGeo = [&](const Eigen::Vector3d& Y)
		{
			return pointToPlaneResidual(Y.x(), Y.y(), Y.z(), nrm.x(), nrm.y(),
			                            nrm.z(), dpl);
		};
		const auto rPhoto = [&](const Eigen::Vector3d& Y)
		{
			double u, v;
			denseProject(Y.x(), Y.y(), 1 / Y.z(), fx, fy, cx, cy, u, v);
			return smoothGrey(u, v);
		};
		double Jg[6], Jp[6], ng[6], np[6];
		pointToPlaneJacobian(X.x(), X.y(), X.z(), nrm.x(), nrm.y(), nrm.z(),
		                     Jg);
		double u, v;
		denseProject(X.x(), X.y(), 1 / X.z(), fx, fy, cx, cy, u, v);
		const Eigen::Vector2d g = smoothGreyGradient(u, v);
		photometricJacobian(X.x(), X.y(), X.z(), 1 / X.z(), g.x(), g.y(), fx,
		                    fy, Jp);
		for (int k = 0; k < 6; k++)
		{
			Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
			d(k) = h;
			const Eigen::Vector3d Xp = movedPoint(R, t, p, d),
			                      Xm = movedPoint(R, t, p, -d);
			ng[k] = (rGeo(Xp) - rGeo(Xm)) / (2 * h);
			np[k] = (rPhoto(Xp) - rPhoto(Xm)) / (2 * h);
		}
		EXPECT_LT(geo.add(Jg, ng), tol) << "point-to-plane, sample " << n;
		EXPECT_LT(photo.add(Jp, np), tol) << "photometric, sample " << n;
		// the float instantiation (the one the alignment runs): the same
		// to float precision
		float Jgf[6], Jpf[6];
		pointToPlaneJacobian(float(X.x()), float(X.y()), float(X.z()),
		                     float(nrm.x()), float(nrm.y()), float(nrm.z()),
		                     Jgf);
		photometricJacobian(float(X.x()), float(X.y()), float(X.z()),
		                    1.f / float(X.z()), float(g.x()), float(g.y()),
		                    float(fx), float(fy), Jpf);
		EXPECT_LT(inFloat.add(Jgf, Jg), 1e-5) << "point-to-plane, sample " << n;
		EXPECT_LT(inFloat.add(Jpf, Jp), 1e-5) << "photometric, sample " << n;
	}
	std::printf(
	    "point-to-plane: max abs %.2e, rel %.2e; photometric: max abs "
	    "%.2e, rel %.2e; float: rel %.2e\n",
	    geo.abs, geo.rel, photo.abs, photo.rel, inFloat.rel);
}

namespace
{
/** The translation information (Schur complement, rotation free) of an
 * alignment of \a cur to \a ref, depth only, with a weak translation prior
 * (the inertial filter's: its information measured on the geometry) or
 * without (the linearised one). */
Eigen::Matrix3d translationInfo(const cv::Mat& refDepth,
                                const cv::Mat& curDepth, bool withPrior)
{
	const AnchorParams p = params320();
	DenseFrame ref, cur;
	ref.build(cv::Mat(), refDepth, K320(), p);
	ref.prepareReference(p);
	cur.build(cv::Mat(), curDepth, K320(), p);
	TranslationPrior prior;
	prior.info = Eigen::Matrix3d::Identity() / (0.5 * 0.5);
	const DenseAlignResult a = alignDense(ref, cur, Eigen::Matrix3d::Identity(),
	                                      Eigen::Vector3d::Zero(), p, nullptr,
	                                      0, withPrior ? &prior : nullptr);
	EXPECT_TRUE(a.ok) << a.why;
	return translationInformation(a.information, 0);
}

/** A fronto-parallel wall at 2 m, depth noise 5 mm per pixel. */
cv::Mat noisyWall(uint32_t seed)
{
	std::mt19937 rng(seed);
	std::normal_distribution<float> n(0, 0.005f);
	cv::Mat d(240, 320, CV_32FC1);
	for (int v = 0; v < d.rows; v++)
		for (int u = 0; u < d.cols; u++) d.at<float>(v, u) = 2.f + n(rng);
	return d;
}
}  // namespace

// Issue 52: a flat wall's noisy normals give the linearised alignment
// information along the wall that sliding along it does not bear out: with
// a translation prior (the inertial filter's) the information is measured
// on the geometry, and the wall keeps only its normal's. A furnished room
// keeps what it has.
TEST(DenseAlign, TheInformationAlongAFlatWallIsMeasuredAsNone)
{
	const cv::Mat a = noisyWall(1), b = noisyWall(2);
	const Eigen::Matrix3d lin = translationInfo(a, b, false),
	                      meas = translationInfo(a, b, true);
	std::printf(
	    "flat wall: information x %.3g -> %.3g, y %.3g -> %.3g, z "
	    "%.3g -> %.3g [1/m^2]\n",
	    lin(0, 0), meas(0, 0), lin(1, 1), meas(1, 1), lin(2, 2), meas(2, 2));
	// the linearised one: the in-plane directions pinned to ~1 cm (the
	// noisy normals), the normal to well under 1 mm
	EXPECT_GT(lin(0, 0), 1 / (0.02 * 0.02));
	EXPECT_GT(lin(1, 1), 1 / (0.02 * 0.02));
	// measured: along the wall under a tenth of that, the normal kept
	EXPECT_LT(meas(0, 0), 0.1 * lin(0, 0));
	EXPECT_LT(meas(1, 1), 0.1 * lin(1, 1));
	EXPECT_GT(meas(2, 2), 0.9 * lin(2, 2));

	// the synthetic room's walls and floor in view, with the same noise:
	// the directions their corners pin (in the exact depth) stay, the one
	// they do not (along the two walls in view, x) has only the noise's and
	// loses it
	Pair s = pairAt(0.1);
	const Eigen::Matrix3d exact =
	    translationInfo(s.ref.depth, s.cur.depth, false);
	std::mt19937 rng(3);
	std::normal_distribution<float> n(0, 0.005f);
	for (cv::Mat* d : {&s.ref.depth, &s.cur.depth})
		for (auto it = d->begin<float>(); it != d->end<float>(); ++it)
			*it += n(rng);
	const Eigen::Matrix3d linRoom =
	                          translationInfo(s.ref.depth, s.cur.depth, false),
	                      measRoom =
	                          translationInfo(s.ref.depth, s.cur.depth, true);
	const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(linRoom);
	int pinned = 0, free = 0;
	for (int k = 0; k < 3; k++)
	{
		const Eigen::Vector3d d = es.eigenvectors().col(k);
		const double real = d.dot(exact * d), before = d.dot(linRoom * d),
		             after = d.dot(measRoom * d);
		std::printf(
		    "room: information along (%.2f %.2f %.2f): exact depth "
		    "%.3g, noisy %.3g, measured %.3g\n",
		    d.x(), d.y(), d.z(), real, before, after);
		if (real > 0.5 * before)
		{
			++pinned;
			EXPECT_GT(after, 0.7 * before) << "room, " << d.transpose();
		}
		else
		{
			++free;
			EXPECT_LT(after, 0.1 * before) << "room, " << d.transpose();
		}
	}
	EXPECT_EQ(pinned, 2);
	EXPECT_EQ(free, 1);
}
