// bims-odom CONFIG.ini IN.rawlog -o TRAJ.txt [--calib CALIB.ini]
//           [--mode imu|vision] [--gyro-aid true|false] [--csv FRAMES.csv]
// Egomotion alone: writes the camera trajectory T_WC in the TUM format and a
// per-stage timing summary. Works with or without IMU data in the rawlog
// (mode = vision for data without IMU).
#include <bims/common/app.h>
#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/common/trajectory.h>
#include <bims/ego/flags.h>
#include <bims/ego/replay.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/filesystem.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
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
		        ' ', "0.1");
		    TCLAP::UnlabeledValueArg<std::string> cfgArg(
		        "CONFIG", "experiment .ini", true, "", "CONFIG.ini", cmd);
		    TCLAP::UnlabeledValueArg<std::string> inArg(
		        "RAWLOG", "input rawlog", true, "", "IN.rawlog", cmd);
		    TCLAP::ValueArg<std::string> outArg(
		        "o", "out", "output TUM trajectory", true, "", "TRAJ.txt", cmd);
		    TCLAP::ValueArg<std::string> calibArg(
		        "c", "calib",
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
		    TCLAP::ValueArg<size_t> maxArg(
		        "", "max-frames", "stop after N frames", false, 0, "N", cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "no progress line", cmd);
		    cmd.parse(argc, argv);

		    const std::string cfgPath = cfgArg.getValue();
		    if (!mrpt::system::fileExists(cfgPath))
			    throw UsageError(cfgPath + ": no such config file");
		    mrpt::config::CConfigFile cfg(cfgPath);
		    checkExperimentSections(cfg);
		    ego::EgoConfig ec;
		    ec.loadFromConfigFile(cfg, false);
		    if (!calibArg.getValue().empty())
		    {
			    const std::string cp = calibArg.getValue();
			    if (!mrpt::system::fileExists(cp))
				    throw UsageError(cp + ": no such calibration file");
			    mrpt::config::CConfigFile cal(cp);
			    checkExperimentSections(cal);
			    if (cal.sectionExists("calibration"))
				    ec.calibration.loadFromConfigFile(cal);
			    if (cal.sectionExists("camera"))
				    ec.camera.loadFromConfigFile(cal);
			    if (cal.sectionExists("sensors"))
				    ec.sensors.loadFromConfigFile(cal);
		    }
		    if (modeArg.isSet())
		    {
			    if (modeArg.getValue() != "imu" &&
			        modeArg.getValue() != "vision")
				    throw UsageError("--mode must be imu or vision");
			    ec.odometry.mode = modeArg.getValue();
		    }
		    if (aidArg.isSet())
		    {
			    const std::string& a = aidArg.getValue();
			    if (a != "true" && a != "false")
				    throw UsageError("--gyro-aid must be true or false");
			    ec.odometry.gyro_aid = (a == "true");
		    }
		    if (ec.odometry.mode == "imu" && !ec.calibration.has_R_IC)
			    throw ConfigError(
			        cfgPath +
			        ": [calibration] R_IC missing (needed by [odometry] mode = "
			        "imu; give it in the config or with --calib)");

		    ego::Odometry odo(ec);
		    Trajectory traj;
		    std::vector<double> msIn, msTrack, msMotion, msEgo;
		    std::ofstream csv;
		    if (csvArg.isSet())
		    {
			    csv.open(csvArg.getValue());
			    if (!csv)
				    throw std::runtime_error(csvArg.getValue() +
				                             ": cannot write");
			    csv << "t,flags,rotation,correspondences,inliers,residual_m,"
			           "tracks,"
			           "ms_input,ms_track,ms_motion\n";
		    }
		    ego::ReplayOptions ro;
		    ro.max_frames = maxArg.getValue();
		    ro.progress = !quiet.getValue();
		    const auto st = ego::replayRawlog(
		        inArg.getValue(), odo,
		        [&](const ego::FrameEgomotion& r, const auto&)
		        {
			        if (r.flags & ego::kFlagOutOfOrder ||
			            r.flags & ego::kFlagBadImage)
				        return;  // no pose for this frame
			        traj.push_back({r.t, r.T_WC});
			        msIn.push_back(r.ms_input);
			        msTrack.push_back(r.ms_track);
			        msMotion.push_back(r.ms_motion);
			        msEgo.push_back(r.ms_track + r.ms_motion);
			        if (csv.is_open())
			        {
				        char buf[256];
				        std::snprintf(
				            buf, sizeof(buf),
				            "%.6f,%s,%s,%d,%d,%.5f,%zu,%.3f,%.3f,%.3f\n", r.t,
				            ego::flagsToString(r.flags).c_str(),
				            ego::toString(r.R_source), r.correspondences,
				            r.inliers, r.residual_rms_m, r.tracks.size(),
				            r.ms_input, r.ms_track, r.ms_motion);
				        csv << buf;
			        }
		        },
		        ro);
		    if (traj.empty())
			    throw std::runtime_error(
			        inArg.getValue() +
			        ": no usable RGB-D frame (check [sensors] "
			        "rgbd_label)");
		    saveTumTrajectory(
		        outArg.getValue(), traj,
		        "bims-odom mode=" + ec.odometry.mode +
		            " gyro_aid=" + (ec.odometry.gyro_aid ? "true" : "false"));
		    std::fprintf(
		        stderr,
		        "bims-odom: %zu frames (%zu flagged), %zu IMU samples; mode=%s "
		        "gyro_aid=%s\n"
		        "bims-odom: ms/frame median (p95): input %.2f (%.2f), tracking "
		        "%.2f (%.2f), motion %.2f (%.2f), egomotion %.2f (%.2f)\n",
		        st.frames, st.flagged, st.imu, ec.odometry.mode.c_str(),
		        ec.odometry.gyro_aid ? "true" : "false", percentile(msIn, 0.5),
		        percentile(msIn, 0.95), percentile(msTrack, 0.5),
		        percentile(msTrack, 0.95), percentile(msMotion, 0.5),
		        percentile(msMotion, 0.95), percentile(msEgo, 0.5),
		        percentile(msEgo, 0.95));
		    return 0;
	    });
}
