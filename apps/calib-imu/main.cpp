// bims-calib-imu CONFIG.ini IN.rawlog [--calib CALIB.ini] [-o OUT.ini]
// Estimates R_IC (camera {C} in IMU {I}, p_I = R_IC p_C) from a sequence:
// vision-only odometry gives each inter-frame rotation R_CprevC, the raw
// gyro integrated over the same interval gives R_IprevI, and R_IC solves
// Log(R_IprevI) = R_IC Log(R_CprevC) robustly (docs/ego.md). When the
// config already holds an R_IC, the angle between the two is reported.
#include <bims/common/app.h>
#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/common/output_paths.h>
#include <bims/ego/flags.h>
#include <bims/ego/rotation_calibration.h>
#include <bims/ego/so3.h>
#include <bims/source/odometry_replay.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/filesystem.h>

#include <cmath>
#include <cstdio>
#include <deque>
#include <fstream>
#include <sstream>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-calib-imu",
	    [&]()
	    {
		    using namespace bims;
		    TCLAP::CmdLine cmd(
		        "Estimates the IMU-camera rotation R_IC from gyro vs visual "
		        "inter-frame rotations.",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> cfgArg(
		        "CONFIG", "experiment .ini", true, "", "CONFIG.ini", cmd);
		    TCLAP::UnlabeledValueArg<std::string> inArg(
		        "RAWLOG", "input rawlog (RGB-D + IMU)", true, "", "IN.rawlog",
		        cmd);
		    TCLAP::ValueArg<std::string> calibArg(
		        "", "calib",
		        "extra .ini with [calibration] [camera] [sensors] (its R_IC, "
		        "if any, "
		        "is the reference the estimate is compared with)",
		        false, "", "CALIB.ini", cmd);
		    TCLAP::ValueArg<std::string> outArg(
		        "o", "out", "write the estimate as a [calibration] section",
		        false, "", "OUT.ini", cmd);
		    TCLAP::ValueArg<double> minAngle(
		        "", "min-angle-deg",
		        "skip frame pairs rotating less than this (0.3)", false, 0.3,
		        "DEG", cmd);
		    TCLAP::ValueArg<double> thr(
		        "", "inlier-deg",
		        "inlier limit on the rotation-vector residual (0.3)", false,
		        0.3, "DEG", cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv, {{"-c", "--calib"}});
		    bims::checkOutputsSpareInputs(
		        {cfgArg.getValue(), inArg.getValue(), calibArg.getValue()},
		        bims::givenValues(outArg));

		    const std::string cfgPath = cfgArg.getValue();
		    ego::EgoConfig ec;
		    ec.loadFromFile(cfgPath);
		    if (calibArg.isSet())
		    {
			    if (!mrpt::system::fileExists(calibArg.getValue()))
				    throw UsageError(calibArg.getValue() + ": no such file");
			    bims::checkIniFile(calibArg.getValue());
			    mrpt::config::CConfigFile cal(calibArg.getValue());
			    checkExperimentSections(cal);
			    ec.overrideSensorSections(cal);
		    }
		    const bool haveRef = ec.calibration.has_R_IC;
		    const Eigen::Matrix3d R_ref = ec.calibration.R_IC;
		    // Vision only, and R_IC unknown to the odometry (no gyro aid from
		    // it).
		    ec.odometry.mode = ego::OdometryMode::Vision;
		    ec.calibration.has_R_IC = false;
		    ego::Odometry odo(ec);

		    std::deque<ego::ImuSample> imu;
		    std::vector<ego::RotationPair> pairs;
		    double tPrev = NAN;
		    source::ReplayOptions ro;
		    ro.progress = !quiet.getValue();
		    ro.imu_wait_s = 0.5;
		    const double off = ec.calibration.time_offset_s;
		    const auto st = source::replayRawlog(
		        inArg.getValue(), odo,
		        [&](const ego::FrameEgomotion& r, const auto&)
		        {
			        if (r.ok() && !(r.flags & ego::kFlagFirstFrame) &&
			            std::isfinite(tPrev))
			        {
				        const auto R_I =
				            ego::integrateGyro(imu, tPrev + off, r.t + off);
				        if (R_I)
				        {
					        Eigen::Matrix3d R_C;
					        for (int i = 0; i < 3; i++)
						        for (int j = 0; j < 3; j++)
							        R_C(i, j) =
							            r.T_CprevC.getRotationMatrix()(i, j);
					        pairs.push_back({*R_I, R_C});
				        }
			        }
			        if (!(r.flags & ego::kFlagOutOfOrder)) tPrev = r.t;
			        while (imu.size() > 2 && imu[1].t < tPrev + off - 0.5)
				        imu.pop_front();
		        },
		        ro, [&](const ego::ImuSample& s) { imu.push_back(s); });
		    if (st.imu == 0)
			    throw std::runtime_error(
			        inArg.getValue() +
			        ": no IMU observation (check [sensors] imu_label)");

		    const auto res = ego::estimateRotationIC(pairs, minAngle.getValue(),
		                                             thr.getValue());
		    std::printf(
		        "bims-calib-imu: %zu frames, %zu IMU samples, %zu frame pairs, "
		        "%d "
		        "rotating > %.2f deg, %d inliers, residual RMS %.3f deg, "
		        "conditioning %.3f\n",
		        st.frames, st.imu, pairs.size(), res.informative,
		        minAngle.getValue(), res.inliers, res.rms_deg,
		        res.conditioning);
		    if (!res.ok)
			    throw std::runtime_error(
			        "R_IC not observable from this sequence (too few "
			        "informative "
			        "pairs, or rotation about a single axis): rotate the rig "
			        "about "
			        "at least two axes");
		    std::printf("R_IC =");
		    for (int i = 0; i < 3; i++)
			    for (int j = 0; j < 3; j++)
				    std::printf(" %.6f", res.R_IC(i, j));
		    std::printf("\n");
		    if (haveRef)
			    std::printf(
			        "bims-calib-imu: angle to the configured R_IC: %.3f deg\n",
			        ego::angleSO3(R_ref.transpose() * res.R_IC) * 180 / M_PI);
		    if (outArg.isSet())
		    {
			    std::ostringstream f;
			    f << "# bims-calib-imu estimate from " << inArg.getValue()
			      << "\n"
			      << "[calibration]\n; p_I = R_IC p_C, row major\nR_IC =";
			    char buf[32];
			    for (int i = 0; i < 3; i++)
				    for (int j = 0; j < 3; j++)
				    {
					    std::snprintf(buf, sizeof(buf), " %.9f",
					                  res.R_IC(i, j));
					    f << buf;
				    }
			    f << "\ntime_offset_s = " << off << "\n";
			    bims::writeFileAtomically(outArg.getValue(), f.str());
		    }
		    return 0;
	    });
}
