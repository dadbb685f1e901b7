#include <bims/apps/app.h>
#include <bims/apps/odometry_run.h>
#include <bims/apps/output_checks.h>
#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/common/so3.h>
#include <bims/common/stats.h>
#include <bims/ego/flags.h>
#include <bims/io/output_paths.h>
#include <bims/io/rawlog.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/filesystem.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

namespace bims::apps
{

void overrideSensorSectionsFrom(ego::EgoConfig& ec, const std::string& calib,
                                const std::string& noSuch)
{
	if (!mrpt::system::fileExists(calib))
		throw UsageError(calib + ": no such " + noSuch);
	const auto cal = openIniFile(calib);
	checkExperimentSections(*cal);
	ec.overrideSensorSections(*cal);
}

ego::EgoConfig egoConfigOption(const std::string& path)
{
	ego::EgoConfig ec;
	try
	{
		ec.loadFromFile(path);
	}
	catch (const ConfigFileMissing& e)
	{
		throw UsageError(e.what());
	}
	return ec;
}

ego::EgoConfig odometryConfig(const OdometryRunOptions& o)
{
	ego::EgoConfig ec = egoConfigOption(o.config);
	if (!o.calib.empty())
		overrideSensorSectionsFrom(ec, o.calib, "calibration file");
	if (o.mode)
	{
		try
		{
			ec.odometry.mode = parseChoice<ego::OdometryMode>(*o.mode);
		}
		catch (const std::invalid_argument& e)
		{
			throw UsageError(std::string("--mode: ") + e.what());
		}
	}
	if (o.gyro_aid)
	{
		if (*o.gyro_aid != "true" && *o.gyro_aid != "false")
			throw UsageError("--gyro-aid must be true or false");
		ec.odometry.gyro_aid = (*o.gyro_aid == "true");
	}
	if (ec.odometry.mode == ego::OdometryMode::Imu && !ec.calibration.has_R_IC)
		throw ConfigError(
		    o.config +
		    ": [calibration] R_IC missing (needed by [odometry] mode = "
		    "imu; give it in the config or with --calib)");
	return ec;
}

TrackerTruth trackerAgainstTruth(const ego::FrameEgomotion& r,
                                 const cv::Mat& prevDepth,
                                 const Eigen::Matrix3d& K,
                                 const mrpt::poses::CPose3D& T_CprevC,
                                 double dt)
{
	TrackerTruth out;
	const Eigen::Matrix3d R = T_CprevC.getRotationMatrix().asEigen();
	const Eigen::Vector3d t(T_CprevC.x(), T_CprevC.y(), T_CprevC.z());
	out.rate_deg_s = angleSO3(R) * 180 / M_PI / dt;
	// True position of a previous-image feature.
	const auto truth = [&](const cv::Point2f& x, Eigen::Vector2d& y)
	{
		const float z = ego::depthAt(prevDepth, x);
		if (z <= 0) return false;
		const Eigen::Vector3d q =
		    K * (R.transpose() * (ego::backProject(K, x, z) - t));
		y = q.head<2>() / q.z();
		return q.z() > 0;
	};
	Eigen::Vector2d y;
	for (const auto& x : r.attempted) out.attempted_with_depth += truth(x, y);
	for (const auto& tr : r.tracks)
		if (truth(tr.prev, y) &&
		    std::hypot(y.x() - tr.cur.x, y.y() - tr.cur.y) < 2.0)
			++out.tracked_within_2px;
	return out;
}

const char* odometryCsvHeader()
{
	return "t,flags,rotation,correspondences,inliers,residual_m,tracks,"
	       "ms_input,ms_track,ms_motion,true_rate_deg_s,"
	       "attempted_with_depth,tracked_within_2px,"
	       "anchor_keyframe,anchor_inliers,anchor_inlier_fraction,"
	       "anchor_overlap,anchor_coverage,anchor_guess,anchor_correction_m,"
	       "anchor_correction_deg,anchor_excluded,anchor_seen_through,"
	       "ms_anchor,anchor_note,degenerate_dirs,inertial_nis,"
	       "position_info_min,position_info_max,vx,vy,vz,gx,gy,gz,"
	       "acc_bias_x,acc_bias_y,acc_bias_z\n";
}

std::string odometryCsvLine(const ego::FrameEgomotion& r,
                            const TrackerTruth& truth)
{
	char buf[768];
	const auto& a = r.anchor;
	std::snprintf(
	    buf, sizeof(buf),
	    "%.6f,%s,%s,%d,%d,%.5f,%zu,%.3f,%.3f,%.3f,%.3f,%d,%d,"
	    "%d,%d,%.3f,%.3f,%.3f,%d,%.4f,%.3f,%.3f,%d,%.3f,%s,%d,%.3f,%.4g,%.4g,"
	    "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n",
	    r.t, ego::flagsToString(r.flags).c_str(), ego::toString(r.R_source),
	    r.correspondences, r.inliers, r.residual_rms_m, r.tracks.size(),
	    r.ms_input, r.ms_track, r.ms_motion, truth.rate_deg_s,
	    truth.attempted_with_depth, truth.tracked_within_2px, a.keyframe,
	    a.inliers, a.inlier_fraction, a.overlap, a.coverage, a.guess,
	    a.correction_m, a.correction_deg, a.excluded_fraction, a.seen_through,
	    r.ms_anchor, a.why.empty() ? "-" : a.why.c_str(), r.degenerate,
	    r.inertial_nis, r.position_information.x(), r.position_information.z(),
	    r.v_W.x(), r.v_W.y(), r.v_W.z(), r.gravity_W.x(), r.gravity_W.y(),
	    r.gravity_W.z(), r.acc_bias.x(), r.acc_bias.y(), r.acc_bias.z());
	return buf;
}

namespace
{
/** An attitude output of bims-odom (translation 0) written to \a path when
 * asked for; none to write is an error: \a what, then \a whyNone. */
void saveAttitude(const std::optional<std::string>& path,
                  const Trajectory& poses, const std::string& what,
                  const std::string& whyNone, const std::string& rotation)
{
	if (!path) return;
	if (poses.empty()) throw std::runtime_error(what + ": " + whyNone);
	saveTumTrajectory(*path, poses,
	                  "bims-odom: " + rotation +
	                      " at each frame (translation not estimated: 0)");
}
}  // namespace

namespace
{
/** Refuses outputs that are inputs and outputs whose folder is not there,
 * before any work. */
void checkOdometryFiles(const OdometryRunOptions& o)
{
	std::vector<std::string> outputs = {o.out};
	if (o.csv) outputs.insert(outputs.begin(), *o.csv);
	if (o.attitude) outputs.insert(outputs.begin(), *o.attitude);
	if (o.gravity_attitude)
		outputs.insert(outputs.begin(), *o.gravity_attitude);
	std::vector<std::string> inputs = {o.config, o.rawlog, o.calib,
	                                   o.masks.value_or(""), o.gt.value_or("")};
	// the masks fed back are inputs too (-o MASKS/000000.png)
	if (o.masks)
		for (auto& f : frameFilesIn(*o.masks)) inputs.push_back(std::move(f));
	checkOutputsSpareInputs(inputs, outputs);
	// written at the end of the run: a folder that is not there is said now
	checkOutputFilesWritable(outputs);
}

/** What a run collects frame by frame: the poses, the attitudes, the stage
 * times and the CSV lines (with the tracker against the ground truth). */
class OdometryRecorder
{
 public:
	OdometryRecorder(const OdometryRunOptions& o, const ego::EgoConfig& ec,
	                 const ego::Odometry& odo)
	    : o_(o), ec_(ec), odo_(odo)
	{
		if (o.csv)
		{
			csv_ = std::make_unique<AppendFile>(*o.csv);
			csv_->append(odometryCsvHeader());
		}
		if (o.gt) gt_ = loadTumTrajectory(*o.gt);
	}

	void add(const ego::FrameEgomotion& r,
	         const mrpt::obs::CObservation3DRangeScan& scan)
	{
		if (r.flags & ego::kFlagOutOfOrder || r.flags & ego::kFlagBadImage)
			return;  // no pose for this frame
		traj.push_back({r.t, r.T_WC});
		if (const auto R = o_.attitude ? odo_.imuRotation(r.t) : std::nullopt)
			attitude.push_back({r.t, ego::toPose(*R, Eigen::Vector3d::Zero())});
		if (o_.gravity_attitude && r.inertial)
		{
			const Eigen::Matrix3d R = ego::levellingRotation(r.gravity_W);
			const Eigen::Matrix3d R_WC = r.T_WC.getRotationMatrix().asEigen();
			levelled.push_back(
			    {r.t, ego::toPose(R * R_WC, Eigen::Vector3d::Zero())});
		}
		msIn.push_back(r.ms_input);
		msTrack.push_back(r.ms_track);
		msMotion.push_back(r.ms_motion);
		msEgo.push_back(r.ms_track + r.ms_motion);
		if (csv_) csv_->append(odometryCsvLine(r, truthOf(r, scan)));
	}

	void closeCsv()
	{
		if (csv_) csv_->close();
	}

	Trajectory traj, attitude, levelled;
	std::vector<double> msIn, msTrack, msMotion, msEgo;

 private:
	/** The tracker's accuracy against the ground truth (none without). */
	TrackerTruth truthOf(const ego::FrameEgomotion& r,
	                     const mrpt::obs::CObservation3DRangeScan& scan)
	{
		TrackerTruth truth;
		ego::RgbdFrame cur;
		if (!gt_.empty() && ego::rgbdFrameFrom(scan, ec_.camera, cur).empty())
		{
			// ground-truth poses nearest to the stamps (within 5 ms)
			const StampedPose* g1 = poseNear(gt_, r.t, 5e-3);
			const StampedPose* g0 = poseNear(gt_, prevT_, 5e-3);
			if (g0 && g1 && !prevDepth_.empty())
				truth = trackerAgainstTruth(r, prevDepth_, cur.K,
				                            g1->T_WC - g0->T_WC, r.t - prevT_);
			prevDepth_ = cur.depth;
		}
		prevT_ = r.t;
		return truth;
	}

	const OdometryRunOptions& o_;
	const ego::EgoConfig& ec_;
	const ego::Odometry& odo_;
	std::unique_ptr<AppendFile> csv_;  // each line checked
	Trajectory gt_;
	cv::Mat prevDepth_;
	double prevT_ = 0;
};

/** The attitude outputs (--attitude, --gravity-attitude), each when asked. */
void saveAttitudes(const OdometryRunOptions& o, const OdometryRecorder& rec)
{
	saveAttitude(o.attitude, rec.attitude, o.rawlog + ": --attitude",
	             "no frame has an IMU attitude (no IMU samples with [sensors] "
	             "imu_label, or no [calibration] R_IC)",
	             "the IMU attitude filter's R_WC = R_WI R_IC");
	saveAttitude(o.gravity_attitude, rec.levelled,
	             o.rawlog + ": --gravity-attitude",
	             "the inertial filter carried no frame ([inertial] enable = "
	             "false, mode = vision, no IMU samples or no [calibration] "
	             "R_IC)",
	             "the odometry's R_WC levelled by the inertial filter's "
	             "gravity");
}

/** The run's summary on stderr: frames, stage times, masks, IMU notes. */
void reportOdometry(const OdometryRunOptions& o, const ReplayOptions& ro,
                    const ReplayStats& st, const OdometryRecorder& rec,
                    const char* mode, const char* aid)
{
	const auto pIn = Percentiles::of(rec.msIn),
	           pTrack = Percentiles::of(rec.msTrack),
	           pMotion = Percentiles::of(rec.msMotion),
	           pEgo = Percentiles::of(rec.msEgo);
	std::fprintf(
	    stderr,
	    "bims-odom: %zu frames (%zu with the motion not measured), %zu IMU "
	    "samples; mode=%s "
	    "gyro_aid=%s\n"
	    "bims-odom: ms/frame median (p95): input %.2f (%.2f), tracking "
	    "%.2f (%.2f), motion %.2f (%.2f), egomotion %.2f (%.2f)\n",
	    st.frames, st.flagged, st.imu, mode, aid, pIn.median, pIn.p95,
	    pTrack.median, pTrack.p95, pMotion.median, pMotion.p95, pEgo.median,
	    pEgo.p95);
	if (o.masks)
		std::fprintf(stderr, "bims-odom: masks of %s for %zu of %zu frames\n",
		             ro.masks_dir.c_str(), st.masksUsed, st.frames);
	else
		std::fprintf(stderr,
		             "bims-odom: no --masks: moving content is left to "
		             "the robust alignment (no mask)\n");
	for (const auto& n : st.imuNotes)
		std::fprintf(stderr, "bims-odom: %s\n", n.c_str());
	if (st.imuRejected)
		std::fprintf(stderr,
		             "bims-odom: %zu IMU samples not used (a value not "
		             "finite or beyond any sensor's range); their frames "
		             "are flagged imu_rejected\n",
		             st.imuRejected);
}
}  // namespace

int runOdometry(const OdometryRunOptions& o)
{
	checkOdometryFiles(o);
	const ego::EgoConfig ec = odometryConfig(o);
	ego::Odometry odo(ec);
	OdometryRecorder rec(o, ec, odo);
	ReplayOptions ro;
	ro.max_frames = o.max_frames;
	ro.progress = o.progress;
	if (o.masks)
	{
		if (!mrpt::system::directoryExists(*o.masks))
			throw std::runtime_error(*o.masks + ": mask directory not found");
		ro.masks_dir = *o.masks;
	}
	const char* mode = choiceName(ec.odometry.mode);
	const char* aid = ec.odometry.gyro_aid ? "true" : "false";
	const std::string header =
	    std::string("bims-odom mode=") + mode + " gyro_aid=" + aid;
	ReplayStats st;
	try
	{
		st = replayRawlog(
		    o.rawlog, odo,
		    [&rec](const ego::FrameEgomotion& r,
		           const mrpt::obs::CObservation3DRangeScan& scan)
		    { rec.add(r, scan); },
		    ro);
	}
	catch (const RawlogError& e)
	{
		// a rawlog cut short: the poses of the frames before the cut are
		// kept, as bims-run keeps its outputs
		if (rec.traj.empty()) throw;
		rec.closeCsv();
		saveTumTrajectory(
		    o.out, rec.traj,
		    header + " (the input ended early: " + e.what() + ")");
		throw std::runtime_error(std::string(e.what()) + "; the poses of the " +
		                         std::to_string(rec.traj.size()) +
		                         " frames before it are in " + o.out);
	}
	if (rec.traj.empty())
		throw std::runtime_error(
		    o.rawlog + ": no usable RGB-D frame (check [sensors] rgbd_label)");
	rec.closeCsv();
	saveTumTrajectory(o.out, rec.traj, header);
	saveAttitudes(o, rec);
	reportOdometry(o, ro, st, rec, mode, aid);
	return 0;
}

}  // namespace bims::apps
