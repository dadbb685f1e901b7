// bims-import-tum FOLDER -o OUT.rawlog [--config cam.ini] [--bonn-gt]
//   [--max-frames N] [--synth-imu [--seed N]] [--gz L]
// Converts a TUM RGB-D-layout folder into a bims rawlog plus OUT_gt/
// (groundtruth.txt, calibration.ini). See docs/eval.md.
#include <bims/common/app.h>
#include <bims/common/output_paths.h>
#include <bims/eval/pose_utils.h>
#include <bims/eval/tum_import.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>
#include <mrpt/config/CConfigFile.h>

#include <cstdio>
#include <filesystem>

#ifdef BIMS_HAVE_SIM
#include <bims/common/config.h>
#include <bims/sim/imu.h>

#include <Eigen/SVD>

namespace
{
/** R_IC and time_offset_s of the synthetic IMU from [calibration]: either
 * the egomotion module's key R_IC (9 reals, row major, p_I = R_IC p_C) or
 * the simulator's R_IC_ypr_deg. Not strict about other keys: the section
 * belongs to those modules, whose readers are. */
void calibrationForSynth(const mrpt::config::CConfigFileBase& cfg,
                         bims::sim::ImuParams& imu)
{
	if (!cfg.sectionExists("calibration")) return;
	bims::ConfigSection s(cfg, "calibration");
	if (s.has("R_IC"))
	{
		const auto v = s.getDoubles("R_IC", {}, 9, -1.0001, 1.0001);
		Eigen::Matrix3d M;
		M << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
		Eigen::JacobiSVD<Eigen::Matrix3d> svd(
		    M, Eigen::ComputeFullU | Eigen::ComputeFullV);
		const Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
		if ((R - M).norm() > 1e-3 || R.determinant() < 0)
			s.fail("R_IC", "not a rotation matrix");
		imu.R_IC = R;
	}
	else if (s.has("R_IC_ypr_deg"))
	{
		const auto y = s.getDoubles("R_IC_ypr_deg", {}, 3, -360, 360);
		imu.setR_IC_ypr(y[0], y[1], y[2]);
	}
	imu.timeOffsetS = s.getDouble("time_offset_s", 0.0, -10.0, 10.0);
}
}  // namespace
#endif

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-import-tum",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "Import a TUM RGB-D-layout folder (rgb.txt, depth.txt, "
		        "optional "
		        "accelerometer.txt, groundtruth.txt) into a rawlog of "
		        "registered "
		        "RGB-D frames plus ground truth in OUT_gt/.",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> folder(
		        "FOLDER", "TUM RGB-D folder", true, "", "FOLDER", cmd);
		    TCLAP::ValueArg<std::string> out(
		        "o", "out", "output rawlog (ground truth goes to OUT_gt/)",
		        true, "", "OUT.rawlog", cmd);
		    TCLAP::ValueArg<std::string> config(
		        "c", "config",
		        "experiment .ini: [camera] intrinsics and depth_scale, "
		        "[import], "
		        "[sensors] (default: TUM 525/319.5/239.5, depth scale 5000)",
		        false, "", "cam.ini", cmd);
		    TCLAP::SwitchArg bonn(
		        "", "bonn-gt",
		        "ground truth is the Bonn RGB-D Dynamic marker pose: convert "
		        "it to "
		        "the camera (same as [import] bonn_gt = true)",
		        cmd);
		    TCLAP::ValueArg<size_t> maxFrames(
		        "", "max-frames", "import only the first N frames (0 = all)",
		        false, 0, "N", cmd);
		    TCLAP::ValueArg<int> gz(
		        "", "gz", "gzip level of the rawlog, 0 = plain (default 1)",
		        false, 1, "L", cmd);
		    TCLAP::SwitchArg synth(
		        "", "synth-imu",
		        "add SYNTHETIC IMU readings (label <imu_label>_SYNTH) "
		        "synthesised "
		        "from the ground truth with bims::sim::synthesizeImu (default "
		        "Xsens MTi-like noise; R_IC and time_offset_s from "
		        "[calibration] of "
		        "--config)",
		        cmd);
		    TCLAP::ValueArg<uint64_t> seed(
		        "s", "seed", "random seed of --synth-imu (default 1)", false, 1,
		        "N", cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv, {{"--output", "--out"}});
		    bims::checkOutputsSpareInputs(
		        {folder.getValue(), config.getValue()},
		        {out.getValue(),
		         bims::eval::groundTruthDirFor(out.getValue())});

		    if (gz.getValue() < 0 || gz.getValue() > 9)
			    throw bims::UsageError("--gz must be in 0..9");
		    bims::eval::ImportParams params;
		    std::unique_ptr<mrpt::config::CConfigFile> cfg;
		    if (config.isSet())
		    {
			    if (!std::filesystem::exists(config.getValue()))
				    throw std::runtime_error(config.getValue() +
				                             ": config file not found");
			    cfg = std::make_unique<mrpt::config::CConfigFile>(
			        config.getValue());
			    params.loadFromConfigFile(*cfg);
		    }
		    else
			    std::fprintf(stderr,
			                 "bims-import-tum: no --config: using the TUM "
			                 "default camera "
			                 "(fx=fy=525, cx=319.5, cy=239.5, 640x480, depth "
			                 "scale 5000)\n");

		    bims::eval::ImportOptions opt;
		    opt.maxFrames = maxFrames.getValue();
		    opt.bonnGt = bonn.getValue();
		    opt.gzLevel = gz.getValue();
		    opt.progress = !quiet.getValue();

		    if (synth.getValue())
		    {
#ifdef BIMS_HAVE_SIM
			    const auto tum =
			        bims::eval::readTumFolder(folder.getValue(), params);
			    if (!tum.hasGroundTruth)
				    throw std::runtime_error(
				        folder.getValue() +
				        ": --synth-imu needs groundtruth.txt to synthesise "
				        "from");
			    bims::Trajectory gt = tum.groundTruth;
			    if (opt.bonnGt || params.bonnGt)
				    for (auto& p : gt)
					    p.T_WC = bims::eval::bonnMarkerToCamera(p.T_WC);
			    bims::sim::ImuParams imu;
			    imu.label = params.imuLabel;
			    if (cfg) calibrationForSynth(*cfg, imu);
			    for (auto& o :
			         bims::sim::synthesizeImu(gt, imu, seed.getValue()))
				    opt.extra.push_back(o);
#else
			    throw bims::UsageError(
			        "--synth-imu: this build has no simulator library "
			        "(libs/sim)");
#endif
		    }

		    const auto sum = bims::eval::importTum(folder.getValue(),
		                                           out.getValue(), params, opt);
		    std::printf("%s: %zu RGB-D frames, %zu IMU observations%s\n",
		                out.getValue().c_str(), sum.frames, sum.imu,
		                synth.getValue() ? " (synthetic)" : "");
		    if (sum.gtPoses || sum.framesWithoutGt)
			    std::printf(
			        "%s/groundtruth.txt: %zu poses (T_WC at the frames' "
			        "stamps%s), "
			        "%zu frames outside the ground truth\n",
			        sum.gtDir.c_str(), sum.gtPoses,
			        (opt.bonnGt || params.bonnGt) ? ", Bonn-converted" : "",
			        sum.framesWithoutGt);
		    else
			    std::printf("%s: no groundtruth.txt in the folder\n",
			                sum.gtDir.c_str());
		    return 0;
	    });
}
