#include <bims/apps/app.h>
#include <bims/apps/calibration_run.h>
#include <bims/apps/frame_range_option.h>
#include <bims/apps/odometry_run.h>
#include <bims/apps/output_checks.h>
#include <bims/common/so3.h>
#include <bims/ego/flags.h>
#include <bims/io/output_paths.h>
#include <bims/io/trajectory.h>
#include <bims/source/frame_source.h>

#include <mrpt/core/format.h>
#include <mrpt/system/filesystem.h>

#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace bims::apps
{
using source::FrameRange;

void RotationPairCollector::addFrame(const ego::FrameEgomotion& r)
{
	if (r.ok() && !(r.flags & ego::kFlagFirstFrame) && std::isfinite(tPrev_))
	{
		const auto R_I = ego::integrateGyro(imu_, tPrev_ + off_, r.t + off_);
		if (R_I)
		{
			pairs_.push_back({*R_I, r.T_CprevC.getRotationMatrix().asEigen()});
		}
	}
	if (!(r.flags & ego::kFlagOutOfOrder)) tPrev_ = r.t;
	while (imu_.size() > 2 && imu_[1].t < tPrev_ + off_ - 0.5) imu_.pop_front();
}

std::string imuCalibrationIni(const Eigen::Matrix3d& R_IC, double time_offset_s,
                              const std::string& rawlog)
{
	std::ostringstream f;
	f << "# bims-calib-imu estimate from " << rawlog << "\n"
	  << "[calibration]\n; p_I = R_IC p_C, row major\nR_IC =";
	char buf[32];
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
		{
			std::snprintf(buf, sizeof(buf), " %.9f", R_IC(i, j));
			f << buf;
		}
	f << "\ntime_offset_s = " << time_offset_s << "\n";
	return f.str();
}

int runImuCalibration(const ImuCalibrationOptions& o)
{
	checkOutputsSpareInputs(
	    {o.config, o.rawlog, o.calib},
	    o.out ? std::vector<std::string>{*o.out} : std::vector<std::string>{});
	ego::EgoConfig ec = egoConfigOption(o.config);
	if (!o.calib.empty()) overrideSensorSectionsFrom(ec, o.calib, "file");
	const bool haveRef = ec.calibration.has_R_IC;
	const Eigen::Matrix3d R_ref = ec.calibration.R_IC;
	// Vision only, and R_IC unknown to the odometry (no gyro aid from it).
	ec.odometry.mode = ego::OdometryMode::Vision;
	ec.calibration.has_R_IC = false;
	ego::Odometry odo(ec);

	const double off = ec.calibration.time_offset_s;
	RotationPairCollector pairs(off);
	ReplayOptions ro;
	ro.progress = o.progress;
	ro.imu_wait_s = 0.5;
	const auto st = replayRawlog(
	    o.rawlog, odo,
	    [&](const ego::FrameEgomotion& r, const auto&) { pairs.addFrame(r); },
	    ro, [&](const sensors::ImuSample& s) { pairs.addImu(s); });
	if (st.imu == 0)
		throw std::runtime_error(
		    o.rawlog + ": no IMU observation (check [sensors] imu_label)");

	const auto res =
	    ego::estimateRotationIC(pairs.pairs(), o.min_angle_deg, o.inlier_deg);
	std::printf(
	    "bims-calib-imu: %zu frames, %zu IMU samples, %zu frame pairs, %d "
	    "rotating > %.2f deg, %d inliers, residual RMS %.3f deg, "
	    "conditioning %.3f\n",
	    st.frames, st.imu, pairs.pairs().size(), res.informative,
	    o.min_angle_deg, res.inliers, res.rms_deg, res.conditioning);
	if (!res.ok)
		throw std::runtime_error(
		    "R_IC not observable from this sequence (too few informative "
		    "pairs, or rotation about a single axis): rotate the rig about "
		    "at least two axes");
	std::printf("R_IC =");
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) std::printf(" %.6f", res.R_IC(i, j));
	std::printf("\n");
	std::printf(
	    "bims-calib-imu: 1-sigma uncertainty %.2f deg about (%.3f %.3f %.3f) "
	    "in {I}, its worst-determined axis\n",
	    res.uncertainty_deg, res.weakAxis_I.x(), res.weakAxis_I.y(),
	    res.weakAxis_I.z());
	if (res.uncertainty_deg > o.max_uncertainty_deg)
		std::fprintf(
		    stderr,
		    "bims-calib-imu: warning: R_IC is poorly observed (1-sigma %.2f "
		    "deg > %.2f): the sequence rotated mostly about one axis; "
		    "record one that rotates about at least two, or keep a nominal "
		    "R_IC\n",
		    res.uncertainty_deg, o.max_uncertainty_deg);
	if (haveRef)
		std::printf("bims-calib-imu: angle to the configured R_IC: %.3f deg\n",
		            angleSO3(R_ref.transpose() * res.R_IC) * 180 / M_PI);
	if (o.out)
		writeFileAtomically(*o.out, imuCalibrationIni(res.R_IC, off, o.rawlog));
	return 0;
}

double largestDepthCorrection(const sensors::DepthCorrectionParams& p,
                              const Eigen::Matrix3d& K, cv::Size size)
{
	sensors::DepthCorrection dc(p);
	double worst = 0;
	cv::Mat fac = dc.factors(K, size);
	cv::minMaxLoc(cv::abs(fac - 1), nullptr, &worst);
	return worst;
}

namespace
{
/** The frames of a depth calibration and their poses T_WC. */
struct CalibFrames
{
	std::vector<ego::RgbdFrame> frames;
	std::vector<Eigen::Matrix4d> poses;
	size_t noPose = 0;  ///< frames without a pose in \a known
};

/** The frames of \a range of the rawlog with their poses: the vision
 * odometry's, or those of \a known (when not empty) near each frame's
 * stamp. */
CalibFrames calibrationFrames(const DepthCalibrationOptions& o,
                              const ego::EgoConfig& ec, const FrameRange& range,
                              const Trajectory& known)
{
	const size_t first = range.first, last = range.last;
	ego::Odometry odo(ec);
	CalibFrames c;
	size_t index = 0;
	ReplayOptions ro;
	ro.progress = o.progress;
	if (last != static_cast<size_t>(-1)) ro.max_frames = last + 1;
	replayRawlog(
	    o.rawlog, odo,
	    [&](const ego::FrameEgomotion& r,
	        const mrpt::obs::CObservation3DRangeScan& scan)
	    {
		    const size_t i = index++;
		    if (i < first || i > last) return;
		    if (r.flags & (ego::kFlagOutOfOrder | ego::kFlagBadImage)) return;
		    mrpt::poses::CPose3D T = r.T_WC;
		    if (!known.empty())
		    {
			    const StampedPose* p = poseNear(known, r.t, 5e-3);
			    if (!p)
			    {
				    ++c.noPose;
				    return;
			    }
			    T = p->T_WC;
		    }
		    ego::RgbdFrame f;
		    if (!ego::rgbdFrameFrom(scan, ec.camera, f).empty()) return;
		    c.frames.push_back(std::move(f));
		    c.poses.push_back(
		        T.getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>()
		            .asEigen());
	    },
	    ro);
	return c;
}
}  // namespace

int runDepthCalibration(const DepthCalibrationOptions& o)
{
	checkOutputsSpareInputs({o.config, o.rawlog, o.poses}, {o.out});
	ego::EgoConfig ec = egoConfigOption(o.config);
	// raw depth, frame-to-frame vision odometry
	ec.odometry.mode = ego::OdometryMode::Vision;
	ec.anchor.enable = false;
	ec.depth_correction.enable = false;
	// (the same A:B rule as bims-run's)
	const FrameRange range =
	    frameRangeOption(o.frames, {o.rawlog}, ec.sensors.rgbd_label);
	Trajectory known;
	if (!o.poses.empty()) known = loadTumTrajectory(o.poses);
	const CalibFrames c = calibrationFrames(o, ec, range, known);
	if (c.frames.empty())
		throw std::runtime_error(
		    o.rawlog +
		    ": no usable RGB-D frame in the range (check --frames, "
		    "[sensors] rgbd_label" +
		    std::string(known.empty() ? ")" : ", --poses stamps)"));
	const ego::DepthFitResult res =
	    ego::estimateDepthCorrection(c.frames, c.poses);
	std::printf(
	    "bims-calib-depth: %zu frames (%zu without a pose), %d pairs, "
	    "%zu residuals; robust RMS point-to-plane %.4f -> %.4f m\n"
	    "bims-calib-depth: correction (1 + delta): left %+.2f %%, right "
	    "%+.2f %%, top %+.2f %%, bottom %+.2f %%, top-left corner %+.2f %%\n",
	    c.frames.size(), c.noPose, res.pairs, res.residuals, res.rms_before_m,
	    res.rms_after_m, 100 * res.left, 100 * res.right, 100 * res.top,
	    100 * res.bottom, 100 * res.corner);
	// A sensor's distortion is a few percent: a larger fit absorbed pose
	// errors (a poor odometry, or moving objects in the stretch).
	const ego::RgbdFrame& f0 = c.frames.front();
	const double worst =
	    largestDepthCorrection(res.params, f0.K, f0.depth.size());
	if (worst > o.max_correction)
		throw std::runtime_error(mrpt::format(
		    "the fitted correction reaches %.1f %% (limit --max-correction "
		    "%.1f %%): the %s do not fit a static scene well enough; give "
		    "--poses (e.g. ground truth) or a slower, longer static stretch "
		    "(nothing written)",
		    100 * worst, 100 * o.max_correction,
		    known.empty() ? "odometry's poses" : "given poses"));
	const std::string note = mrpt::format(
	    "# bims-calib-depth: %zu frames of %s (%s poses), robust RMS %.4f -> "
	    "%.4f m\n",
	    c.frames.size(), mrpt::system::extractFileName(o.rawlog).c_str(),
	    known.empty() ? "vision odometry" : "given", res.rms_before_m,
	    res.rms_after_m);
	writeFileAtomically(o.out, res.params.toIni(note));
	return 0;
}

}  // namespace bims::apps
