// Odometry end to end on rendered frames of a textured room with exact IMU
// data: both modes, with and without the gyro aid, and bad input.
#include <bims/common/config.h>
#include <bims/ego/flags.h>
#include <bims/ego/odometry.h>
#include <gtest/gtest.h>

#include <mrpt/config/CConfigFileMemory.h>

#include "synth_scene.h"

using namespace bims;  // so3.h
using namespace bims::ego;

namespace
{
using test::K320;
const Eigen::Matrix3d kR_IC = expSO3(Eigen::Vector3d(0.3, -1.2, 0.4));

Eigen::Matrix3d R_of(const mrpt::poses::CPose3D& T)
{
	Eigen::Matrix3d R;
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) R(i, j) = T.getRotationMatrix()(i, j);
	return R;
}

struct RunResult
{
	double maxTransErr = 0, maxRotErr_deg = 0;
	int failed = 0;
};

// 1.5 s at 20 Hz with IMU at 200 Hz; errors of T_C0C (relative to the first
// frame, so independent of the world anchoring).
// depthOnly: the frames' images dropped (a LiDAR or time-of-flight camera
// without colour).
RunResult run(EgoConfig cfg, bool withImu, int frames = 30,
              bool depthOnly = false)
{
	cfg.calibration.R_IC = kR_IC;
	cfg.calibration.has_R_IC = true;
	Odometry odo(cfg);
	test::Motion m;
	const double dtImu = 0.005, dtCam = 0.05;
	double tImu = 0;
	RunResult res;
	mrpt::poses::CPose3D T0;
	for (int k = 0; k < frames; k++)
	{
		const double t = k * dtCam;
		if (withImu)
			for (; tImu <= t + 0.03; tImu += dtImu)
				odo.addImu(test::imuAt(m, kR_IC, tImu));
		RgbdFrame f = test::render(m.R(t), m.p(t), K320(), 320, 240, t);
		if (depthOnly) f.grey.release();
		const FrameEgomotion e = odo.processFrame(f);
		if (depthOnly)
		{
			EXPECT_TRUE(e.flags & kFlagNoImage) << k;
			EXPECT_TRUE(e.tracks.empty());
			// no feature count flags a frame that has no image to track in
			EXPECT_FALSE(e.flags & (kFlagTooFewTracks | kFlagTooFewInliers));
		}
		if (k == 0)
		{
			T0 = e.T_WC;
			continue;
		}
		if (!e.ok()) ++res.failed;
		const mrpt::poses::CPose3D Test = e.T_WC - T0;  // T_C0C estimated
		const Eigen::Matrix3d Rt = m.R(0).transpose() * m.R(t);
		const Eigen::Vector3d tt = m.R(0).transpose() * (m.p(t) - m.p(0));
		const Eigen::Vector3d te(Test.x(), Test.y(), Test.z());
		res.maxTransErr = std::max(res.maxTransErr, (te - tt).norm());
		res.maxRotErr_deg =
		    std::max(res.maxRotErr_deg,
		             angleSO3(R_of(Test).transpose() * Rt) * 180 / M_PI);
	}
	return res;
}
}  // namespace

TEST(Odometry, ImuRotationPlusVisualTranslation)
{
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Imu;
	const RunResult r = run(cfg, true);
	EXPECT_EQ(r.failed, 0);
	EXPECT_LT(r.maxRotErr_deg, 0.3);
	EXPECT_LT(r.maxTransErr, 0.03);
}

TEST(Odometry, VisionOnlyWithoutImu)
{
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Vision;
	const RunResult r = run(cfg, false);
	EXPECT_EQ(r.failed, 0);
	EXPECT_LT(r.maxRotErr_deg, 1.0);
	EXPECT_LT(r.maxTransErr, 0.03);
}

TEST(Odometry, RefinedImuRotation)
{
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Imu;
	cfg.translation.refine = TranslationRefine::SE3;
	const RunResult r = run(cfg, true);
	EXPECT_EQ(r.failed, 0);
	EXPECT_LT(r.maxRotErr_deg, 0.3);
	EXPECT_LT(r.maxTransErr, 0.03);
}

TEST(Odometry, DepthOnlyFramesAreMeasuredByTheKeyframeAlignment)
{
	// IMU rotation, the motion measured by the geometric term alone. This
	// box room's few planes leave translation along them unobservable to
	// geometry alone: the translation's accuracy is tested on the
	// simulator's furnished room (EndToEnd.DepthOnlyRunsTiers0And1...).
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Imu;
	const RunResult r = run(cfg, true, 30, true);
	EXPECT_EQ(r.failed, 0);
	EXPECT_LT(r.maxRotErr_deg, 0.3);
	// without an IMU: the alignment estimates the rotation too
	cfg.odometry.mode = OdometryMode::Vision;
	const RunResult v = run(cfg, false, 30, true);
	EXPECT_EQ(v.failed, 0);
	EXPECT_LT(v.maxRotErr_deg, 1.0);
}

TEST(Odometry, DepthOnlyWithoutTheAlignmentIsNotMeasured)
{
	// nothing measures a depth-only frame without the keyframe alignment:
	// its pose is the prediction, and it says so
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Vision;
	cfg.anchor.enable = false;
	Odometry odo(cfg);
	test::Motion m;
	for (int k = 0; k < 3; k++)
	{
		RgbdFrame f = test::render(m.R(k * 0.05), m.p(k * 0.05), K320(), 320,
		                           240, k * 0.05);
		f.grey.release();
		const FrameEgomotion e = odo.processFrame(f);
		EXPECT_TRUE(e.flags & kFlagNoImage);
		if (k > 0)
		{
			EXPECT_FALSE(e.ok()) << flagsToString(e.flags);
			EXPECT_TRUE(std::isfinite(e.T_WC.x()));
		}
	}
	// a frame with an image afterwards: the tracker starts afresh (no
	// previous image), the next one is measured again
	odo.processFrame(
	    test::render(m.R(0.15), m.p(0.15), K320(), 320, 240, 0.15));
	const FrameEgomotion e = odo.processFrame(
	    test::render(m.R(0.2), m.p(0.2), K320(), 320, 240, 0.2));
	EXPECT_TRUE(e.ok()) << flagsToString(e.flags);
	EXPECT_FALSE(e.flags & kFlagNoImage);
}

TEST(Odometry, ImuModeWithoutImuDataFallsBackToVisionAndFlags)
{
	EgoConfig cfg;
	cfg.calibration.has_R_IC = true;
	Odometry odo(cfg);
	test::Motion m;
	FrameEgomotion e;
	for (int k = 0; k < 3; k++)
		e = odo.processFrame(test::render(m.R(k * 0.05), m.p(k * 0.05), K320(),
		                                  320, 240, k * 0.05));
	EXPECT_TRUE(e.flags & kFlagImuMissing);
	EXPECT_EQ(e.R_source, RotationSource::Vision);
	EXPECT_TRUE(e.ok());
}

TEST(Odometry, FlagsBadInputAndKeepsGoing)
{
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Vision;
	Odometry odo(cfg);
	test::Motion m;
	RgbdFrame f0 = test::render(m.R(0), m.p(0), K320(), 320, 240, 0);
	EXPECT_TRUE(odo.processFrame(f0).flags & kFlagFirstFrame);
	// Same timestamp again: out of order, pose unchanged, tracker untouched.
	const FrameEgomotion dup = odo.processFrame(f0);
	EXPECT_TRUE(dup.flags & kFlagOutOfOrder);
	EXPECT_FALSE(dup.ok());
	// No depth at all: too few tracks, flagged, pose stays finite.
	RgbdFrame f1 = test::render(m.R(0.05), m.p(0.05), K320(), 320, 240, 0.05);
	f1.depth.setTo(0);
	const FrameEgomotion e1 = odo.processFrame(f1);
	EXPECT_TRUE(e1.flags & kFlagTooFewTracks);
	EXPECT_FALSE(e1.ok());
	EXPECT_TRUE(std::isfinite(e1.T_WC.x()));
	// Two good frames afterwards (the first still lacks the previous
	// depth): back to normal.
	odo.processFrame(test::render(m.R(0.1), m.p(0.1), K320(), 320, 240, 0.1));
	const FrameEgomotion e3 = odo.processFrame(
	    test::render(m.R(0.15), m.p(0.15), K320(), 320, 240, 0.15));
	EXPECT_TRUE(e3.ok()) << flagsToString(e3.flags);
}

TEST(Odometry, MissingCalibrationKeyIsAClearError)
{
	mrpt::config::CConfigFileMemory cfg(
	    std::string("[odometry]\nmode = imu\n"));
	EgoConfig ec;
	try
	{
		ec.loadFromConfigFile(cfg);
		FAIL() << "expected ConfigError";
	}
	catch (const bims::ConfigError& e)
	{
		EXPECT_NE(std::string(e.what()).find("R_IC"), std::string::npos)
		    << e.what();
		EXPECT_NE(std::string(e.what()).find("calibration"), std::string::npos);
	}
	mrpt::config::CConfigFileMemory bad(
	    std::string("[odometry]\nmode = vision\n[tracker]\nwindw = 21\n"));
	EXPECT_THROW(ec.loadFromConfigFile(bad), bims::ConfigError);
	mrpt::config::CConfigFileMemory notRot(
	    std::string("[calibration]\nR_IC = 1 0 0 0 1 0 0 0 2\n"));
	EXPECT_THROW(ec.loadFromConfigFile(notRot), bims::ConfigError);
	mrpt::config::CConfigFileMemory ok(std::string(
	    "[calibration]\nR_IC = 0 0 1  -1 0 0  0 -1 0\ntime_offset_s = 0.01\n"));
	ec.loadFromConfigFile(ok);
	EXPECT_TRUE(ec.calibration.has_R_IC);
	EXPECT_DOUBLE_EQ(ec.calibration.R_IC(1, 0), -1);
	EXPECT_DOUBLE_EQ(ec.calibration.time_offset_s, 0.01);
}

TEST(Odometry, CorrectLastMotionReplacesThePoseAndTheFallback)
{
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Vision;
	cfg.anchor.enable = false;  // (an anchored pose is not corrected)
	Odometry odo(cfg);
	test::Motion m;
	const auto f0 = test::render(m.R(0), m.p(0), K320(), 320, 240, 0);
	const FrameEgomotion e0 = odo.processFrame(f0);
	// nothing to correct after the first frame
	EXPECT_EQ(odo.correctLastMotion(mrpt::poses::CPose3D(1, 0, 0, 0, 0, 0))
	              .asString(),
	          e0.T_WC.asString());
	const auto f1 = test::render(m.R(0.05), m.p(0.05), K320(), 320, 240, 0.05);
	const FrameEgomotion e1 = odo.processFrame(f1);
	ASSERT_TRUE(e1.ok());
	const mrpt::poses::CPose3D T(0.01, -0.02, 0.03, 0.02, -0.01, 0.015);
	const mrpt::poses::CPose3D T_WC = odo.correctLastMotion(T);
	const mrpt::poses::CPose3D expect = e0.T_WC + T;
	EXPECT_LT((T_WC - expect).norm(), 1e-9);
	EXPECT_LT(std::abs(T_WC.yaw() - expect.yaw()), 1e-9);
	EXPECT_LT(std::abs(T_WC.pitch() - expect.pitch()), 1e-9);
	EXPECT_LT(std::abs(T_WC.roll() - expect.roll()), 1e-9);
	// an unusable next frame falls back on the corrected motion
	RgbdFrame bad = test::render(m.R(0.1), m.p(0.1), K320(), 320, 240, 0.1);
	bad.depth.setTo(0.0f);
	const FrameEgomotion e2 = odo.processFrame(bad);
	EXPECT_FALSE(e2.ok());
	EXPECT_LT((e2.T_CprevC - T).norm(), 1e-9);
	EXPECT_LT(std::abs(e2.T_CprevC.yaw() - T.yaw()), 1e-9);
}

namespace
{
/** Largest angle [deg] between R_WC(k) and R_WC(k-1) R_CprevC(k) over a
 * run with a biased gyro, so that the attitude filter (correcting with
 * gravity and north) and the gyro drift apart while the filter converges. */
double maxChainInconsistencyDeg(bool followConverging)
{
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Imu;
	cfg.odometry.follow_converging_attitude = followConverging;
	cfg.anchor.enable = false;  // (anchored poses chain by construction)
	cfg.calibration.R_IC = kR_IC;
	cfg.calibration.has_R_IC = true;
	cfg.attitude.init_time_s = 1.0;  // the whole run is the converging phase
	Odometry odo(cfg);
	test::Motion m;
	const Eigen::Vector3d bias(0.03, -0.02, 0.04);  // rad/s
	double tImu = 0, worst = 0;
	mrpt::poses::CPose3D prev;
	for (int k = 0; k < 16; k++)
	{
		const double t = k * 0.05;
		for (; tImu <= t + 0.03; tImu += 0.005)
		{
			ImuSample s = test::imuAt(m, kR_IC, tImu);
			s.gyro += bias;
			odo.addImu(s);
		}
		const FrameEgomotion e =
		    odo.processFrame(test::render(m.R(t), m.p(t), K320(), 320, 240, t));
		if (k > 0)
		{
			const mrpt::poses::CPose3D chained = prev + e.T_CprevC;
			const Eigen::Matrix3d d = R_of(chained).transpose() * R_of(e.T_WC);
			worst = std::max(worst, angleSO3(d) * 180 / M_PI);
		}
		prev = e.T_WC;
	}
	return worst;
}
}  // namespace

TEST(Odometry, WorldRotationIntegratesTheGyroWhileTheFilterConverges)
{
	// The map needs one consistent world: each R_WC is the previous one
	// times the inter-frame rotation, also during the filter's convergence.
	EXPECT_LT(maxChainInconsistencyDeg(false), 1e-6);
	// Following the converging filter instead breaks that chain (what the
	// option avoids; fast_rotation lost 0.6 of F1 to it).
	EXPECT_GT(maxChainInconsistencyDeg(true), 0.05);
}

TEST(Odometry, PredictedRotationIsTheGyroRotationOfTheNextFrame)
{
	EgoConfig cfg;
	cfg.odometry.mode = OdometryMode::Imu;
	cfg.calibration.R_IC = kR_IC;
	cfg.calibration.has_R_IC = true;
	Odometry odo(cfg);
	test::Motion m;
	double tImu = 0;
	EXPECT_LT(angleSO3(odo.predictRotation(0.0)), 1e-12);  // no frame yet
	for (int k = 0; k < 8; k++)
	{
		const double t = k * 0.05;
		for (; tImu <= t + 0.03; tImu += 0.005)
			odo.addImu(test::imuAt(m, kR_IC, tImu));
		const Eigen::Matrix3d pred = odo.predictRotation(t);
		const FrameEgomotion e =
		    odo.processFrame(test::render(m.R(t), m.p(t), K320(), 320, 240, t));
		if (k == 0) continue;
		// The motion measured (IMU rotation, pulled by the blend) and the
		// true one, against the prediction made before it.
		EXPECT_LT(angleSO3(pred.transpose() * R_of(e.T_CprevC)) * 180 / M_PI,
		          0.05);
		const Eigen::Matrix3d Rtrue = m.R(t - 0.05).transpose() * m.R(t);
		EXPECT_LT(angleSO3(pred.transpose() * Rtrue) * 180 / M_PI, 0.1);
		EXPECT_GT(angleSO3(Rtrue) * 180 / M_PI, 0.2);  // it does rotate
	}
}
