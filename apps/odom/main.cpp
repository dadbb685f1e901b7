// bims-odom CONFIG.ini IN.rawlog -o TRAJ.txt [--calib CALIB.ini]
//           [--mode imu|vision] [--gyro-aid true|false] [--csv FRAMES.csv]
//           [--masks DIR]
// Egomotion alone: writes the camera trajectory T_WC in the TUM format and a
// per-stage timing summary. Works with or without IMU data in the rawlog
// (mode = vision for data without IMU).
#include <bims/common/app.h>
#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/common/output_paths.h>
#include <bims/common/trajectory.h>
#include <bims/ego/flags.h>
#include <bims/ego/so3.h>
#include <bims/source/odometry_replay.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/filesystem.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <vector>

namespace
{
double percentile(std::vector<double> v, double q)
{
	if (v.empty()) return 0;
	std::sort(v.begin(), v.end());
	return v[std::min(v.size() - 1,
	                  static_cast<size_t>(q * (v.size() - 1) + 0.5))];
}
}  // namespace

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-odom",
	    [&]()
	    {
		    using namespace bims;
		    TCLAP::CmdLine cmd(
		        "Egomotion (IMU attitude + gyro-aided KLT + robust "
		        "translation) "
		        "of an RGB-D(+IMU) rawlog; TUM trajectory output.",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> cfgArg(
		        "CONFIG", "experiment .ini", true, "", "CONFIG.ini", cmd);
		    TCLAP::UnlabeledValueArg<std::string> inArg(
		        "RAWLOG", "input rawlog", true, "", "IN.rawlog", cmd);
		    TCLAP::ValueArg<std::string> outArg(
		        "o", "out", "output TUM trajectory", true, "", "TRAJ.txt", cmd);
		    TCLAP::ValueArg<std::string> calibArg(
		        "", "calib",
		        "extra .ini whose [calibration] [camera] [sensors] override "
		        "the "
		        "config (e.g. bims-sim's OUT_gt/calibration.ini)",
		        false, "", "CALIB.ini", cmd);
		    TCLAP::ValueArg<std::string> modeArg(
		        "", "mode", "override [odometry] mode: imu | vision", false, "",
		        "MODE", cmd);
		    TCLAP::ValueArg<std::string> aidArg(
		        "", "gyro-aid", "override [odometry] gyro_aid: true | false",
		        false, "", "BOOL", cmd);
		    TCLAP::ValueArg<std::string> csvArg(
		        "", "csv", "per-frame details (flags, inliers, stage times)",
		        false, "", "FRAMES.csv", cmd);
		    TCLAP::ValueArg<std::string> masksArg(
		        "", "masks",
		        "folder of moving masks NNNNNN.png (bims-run's OUT/masks, or "
		        "a simulation's ground truth): scan k-1's mask is left out of "
		        "frame k's tracking, as bims-run feeds its segmentation back "
		        "(without it: no mask, moving content is left to the robust "
		        "alignment)",
		        false, "", "DIR", cmd);
		    TCLAP::ValueArg<std::string> gtArg(
		        "", "gt",
		        "ground-truth TUM trajectory: adds to --csv the true angular "
		        "rate and the number of features tracked within 2 px of the "
		        "truth",
		        false, "", "GT.txt", cmd);
		    TCLAP::ValueArg<size_t> maxArg(
		        "", "max-frames", "stop after N frames", false, 0, "N", cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv, {{"-c", "--calib"}});
		    auto outputs = bims::givenValues(csvArg);
		    outputs.push_back(outArg.getValue());
		    checkOutputsSpareInputs(
		        {cfgArg.getValue(), inArg.getValue(), calibArg.getValue(),
		         masksArg.getValue(), gtArg.getValue()},
		        outputs);

		    const std::string cfgPath = cfgArg.getValue();
		    ego::EgoConfig ec;
		    ec.loadFromFile(cfgPath);
		    if (!calibArg.getValue().empty())
		    {
			    const std::string cp = calibArg.getValue();
			    if (!mrpt::system::fileExists(cp))
				    throw UsageError(cp + ": no such calibration file");
			    bims::checkIniFile(cp);
			    mrpt::config::CConfigFile cal(cp);
			    checkExperimentSections(cal);
			    ec.overrideSensorSections(cal);
		    }
		    if (modeArg.isSet())
		    {
			    try
			    {
				    ec.odometry.mode = bims::parseChoice<ego::OdometryMode>(
				        modeArg.getValue());
			    }
			    catch (const std::invalid_argument& e)
			    {
				    throw UsageError(std::string("--mode: ") + e.what());
			    }
		    }
		    if (aidArg.isSet())
		    {
			    const std::string& a = aidArg.getValue();
			    if (a != "true" && a != "false")
				    throw UsageError("--gyro-aid must be true or false");
			    ec.odometry.gyro_aid = (a == "true");
		    }
		    if (ec.odometry.mode == ego::OdometryMode::Imu &&
		        !ec.calibration.has_R_IC)
			    throw ConfigError(
			        cfgPath +
			        ": [calibration] R_IC missing (needed by [odometry] mode = "
			        "imu; give it in the config or with --calib)");

		    ego::Odometry odo(ec);
		    Trajectory traj;
		    std::vector<double> msIn, msTrack, msMotion, msEgo;
		    std::unique_ptr<AppendFile> csv;  // each line checked
		    if (csvArg.isSet())
		    {
			    csv = std::make_unique<AppendFile>(csvArg.getValue());
			    csv->append(
			        "t,flags,rotation,correspondences,inliers,residual_m,"
			        "tracks,"
			        "ms_input,ms_track,ms_motion,true_rate_deg_s,"
			        "attempted_with_depth,tracked_within_2px,"
			        "anchor_keyframe,anchor_inliers,anchor_inlier_fraction,"
			        "anchor_overlap,anchor_coverage,anchor_guess,anchor_"
			        "correction_m,"
			        "anchor_correction_deg,anchor_excluded,anchor_seen_"
			        "through,ms_anchor,"
			        "anchor_note\n");
		    }
		    Trajectory gt;
		    if (gtArg.isSet()) gt = loadTumTrajectory(gtArg.getValue());
		    // Ground-truth pose nearest to t (within 5 ms), or nullptr.
		    const auto gtAt = [&gt](double t) { return poseNear(gt, t, 5e-3); };
		    ego::RgbdFrame prevFrame;
		    double prevT = 0;
		    source::ReplayOptions ro;
		    ro.max_frames = maxArg.getValue();
		    ro.progress = !quiet.getValue();
		    if (masksArg.isSet())
		    {
			    if (!mrpt::system::directoryExists(masksArg.getValue()))
				    throw std::runtime_error(masksArg.getValue() +
				                             ": mask directory not found");
			    ro.masks_dir = masksArg.getValue();
		    }
		    const auto st = source::replayRawlog(
		        inArg.getValue(), odo,
		        [&](const ego::FrameEgomotion& r,
		            const mrpt::obs::CObservation3DRangeScan& scan)
		        {
			        if (r.flags & ego::kFlagOutOfOrder ||
			            r.flags & ego::kFlagBadImage)
				        return;  // no pose for this frame
			        traj.push_back({r.t, r.T_WC});
			        msIn.push_back(r.ms_input);
			        msTrack.push_back(r.ms_track);
			        msMotion.push_back(r.ms_motion);
			        msEgo.push_back(r.ms_track + r.ms_motion);
			        // Tracker accuracy against the ground truth.
			        double rate = NAN;
			        int denom = 0, good = 0;
			        ego::RgbdFrame cur;
			        if (!gt.empty() &&
			            ego::rgbdFrameFrom(scan, ec.camera, cur).empty())
			        {
				        const StampedPose* g1 = gtAt(r.t);
				        const StampedPose* g0 = gtAt(prevT);
				        if (g0 && g1 && !prevFrame.depth.empty())
				        {
					        const mrpt::poses::CPose3D T = g1->T_WC - g0->T_WC;
					        Eigen::Matrix3d R;
					        for (int i = 0; i < 3; i++)
						        for (int j = 0; j < 3; j++)
							        R(i, j) = T.getRotationMatrix()(i, j);
					        const Eigen::Vector3d t(T.x(), T.y(), T.z());
					        rate =
					            ego::angleSO3(R) * 180 / M_PI / (r.t - prevT);
					        // True position of a previous-image feature.
					        const auto truth =
					            [&](const cv::Point2f& x, Eigen::Vector2d& y)
					        {
						        const float z =
						            ego::depthAt(prevFrame.depth, x);
						        if (z <= 0) return false;
						        const Eigen::Vector3d q =
						            cur.K *
						            (R.transpose() *
						             (ego::backProject(cur.K, x, z) - t));
						        y = q.head<2>() / q.z();
						        return q.z() > 0;
					        };
					        Eigen::Vector2d y;
					        for (const auto& x : r.attempted)
						        denom += truth(x, y);
					        for (const auto& tr : r.tracks)
						        if (truth(tr.prev, y) &&
						            std::hypot(y.x() - tr.cur.x,
						                       y.y() - tr.cur.y) < 2.0)
							        ++good;
				        }
				        prevFrame = cur;
			        }
			        prevT = r.t;
			        if (csv)
			        {
				        char buf[512];
				        const auto& a = r.anchor;
				        std::snprintf(
				            buf, sizeof(buf),
				            "%.6f,%s,%s,%d,%d,%.5f,%zu,%.3f,%.3f,%.3f,%.3f,%d,%"
				            "d,"
				            "%d,%d,%.3f,%.3f,%.3f,%d,%.4f,%.3f,%.3f,%d,%.3f,%"
				            "s\n",
				            r.t, ego::flagsToString(r.flags).c_str(),
				            ego::toString(r.R_source), r.correspondences,
				            r.inliers, r.residual_rms_m, r.tracks.size(),
				            r.ms_input, r.ms_track, r.ms_motion, rate, denom,
				            good, a.keyframe, a.inliers, a.inlier_fraction,
				            a.overlap, a.coverage, a.guess, a.correction_m,
				            a.correction_deg, a.excluded_fraction,
				            a.seen_through, r.ms_anchor,
				            a.why.empty() ? "-" : a.why.c_str());
				        csv->append(buf);
			        }
		        },
		        ro);
		    if (traj.empty())
			    throw std::runtime_error(
			        inArg.getValue() +
			        ": no usable RGB-D frame (check [sensors] "
			        "rgbd_label)");
		    if (csv) csv->close();
		    saveTumTrajectory(
		        outArg.getValue(), traj,
		        std::string("bims-odom mode=") +
		            bims::choiceName(ec.odometry.mode) +
		            " gyro_aid=" + (ec.odometry.gyro_aid ? "true" : "false"));
		    std::fprintf(
		        stderr,
		        "bims-odom: %zu frames (%zu flagged), %zu IMU samples; mode=%s "
		        "gyro_aid=%s\n"
		        "bims-odom: ms/frame median (p95): input %.2f (%.2f), tracking "
		        "%.2f (%.2f), motion %.2f (%.2f), egomotion %.2f (%.2f)\n",
		        st.frames, st.flagged, st.imu,
		        bims::choiceName(ec.odometry.mode),
		        ec.odometry.gyro_aid ? "true" : "false", percentile(msIn, 0.5),
		        percentile(msIn, 0.95), percentile(msTrack, 0.5),
		        percentile(msTrack, 0.95), percentile(msMotion, 0.5),
		        percentile(msMotion, 0.95), percentile(msEgo, 0.5),
		        percentile(msEgo, 0.95));
		    if (masksArg.isSet())
			    std::fprintf(stderr,
			                 "bims-odom: masks of %s for %zu of %zu frames\n",
			                 ro.masks_dir.c_str(), st.masksUsed, st.frames);
		    else
			    std::fprintf(stderr,
			                 "bims-odom: no --masks: moving content is left to "
			                 "the robust alignment (no mask)\n");
		    if (st.imuRejected)
			    std::fprintf(
			        stderr,
			        "bims-odom: %zu IMU samples not used (a value not "
			        "finite or beyond any sensor's range); their frames "
			        "are flagged imu_rejected\n",
			        st.imuRejected);
		    return 0;
	    });
}
