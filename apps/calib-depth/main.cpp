// bims-calib-depth CONFIG.ini IN.rawlog [--frames A:B] [--poses TRAJ.txt]
//                  -o OUT.ini
// Fits the depth sensor's smooth distortion (docs/ego.md, "Depth
// correction") to a stretch of a static scene: point-to-plane residuals
// between frame pairs at known poses (--poses, a TUM trajectory) or at the
// poses of bims' own frame-to-frame vision odometry (no ground truth
// needed). Writes a [depth_correction] section to paste into (or include
// with) the experiment .ini.
#include <bims/common/app.h>
#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/common/output_paths.h>
#include <bims/common/trajectory.h>
#include <bims/ego/depth_correction.h>
#include <bims/ego/flags.h>
#include <bims/pipeline/run.h>
#include <bims/source/odometry_replay.h>

#include <mrpt/3rdparty/tclap/CmdLine.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/filesystem.h>

#include <cmath>
#include <cstdio>
#include <fstream>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-calib-depth",
	    [&]()
	    {
		    using namespace bims;
		    TCLAP::CmdLine cmd(
		        "Fits the depth sensor's smooth distortion to a static stretch "
		        "of a recording and writes a [depth_correction] section.",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> cfgArg(
		        "CONFIG", "experiment .ini ([camera], [sensors])", true, "",
		        "CONFIG.ini", cmd);
		    TCLAP::UnlabeledValueArg<std::string> inArg(
		        "RAWLOG", "input rawlog (RGB-D)", true, "", "IN.rawlog", cmd);
		    TCLAP::ValueArg<std::string> framesArg(
		        "", "frames",
		        "3D-scan indices A:B (inclusive) of a stretch without moving "
		        "objects (default: all)",
		        false, "", "A:B", cmd);
		    TCLAP::ValueArg<std::string> posesArg(
		        "", "poses",
		        "TUM trajectory of the camera (e.g. ground truth); default: "
		        "bims' frame-to-frame vision odometry",
		        false, "", "TRAJ.txt", cmd);
		    TCLAP::ValueArg<std::string> outArg(
		        "o", "out", "where to write the [depth_correction] section",
		        true, "", "OUT.ini", cmd);
		    TCLAP::ValueArg<double> maxArg(
		        "", "max-correction",
		        "refuse a fit that corrects any pixel by more than this "
		        "fraction (0.1): the poses did not fit a static scene",
		        false, 0.1, "FRACTION", cmd);
		    TCLAP::SwitchArg quiet("q", "quiet", "no progress line", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    bims::checkOutputsSpareInputs(
		        {cfgArg.getValue(), inArg.getValue(), posesArg.getValue()},
		        {outArg.getValue()});

		    const std::string cfgPath = cfgArg.getValue();
		    ego::EgoConfig ec;
		    ec.loadFromFile(cfgPath);
		    // raw depth, frame-to-frame vision odometry
		    ec.odometry.mode = ego::OdometryMode::Vision;
		    ec.anchor.enable = false;
		    ec.depth_correction.enable = false;
		    // (the same A:B rule as bims-run's)
		    const pipeline::FrameRange range = pipeline::frameRangeOption(
		        framesArg.getValue(), {inArg.getValue()},
		        ec.sensors.rgbd_label);
		    const size_t first = range.first, last = range.last;
		    Trajectory known;
		    if (posesArg.isSet())
			    known = loadTumTrajectory(posesArg.getValue());

		    ego::Odometry odo(ec);
		    std::vector<ego::RgbdFrame> frames;
		    std::vector<Eigen::Matrix4d> poses;
		    size_t index = 0, noPose = 0;
		    source::ReplayOptions ro;
		    ro.progress = !quiet.getValue();
		    if (last != static_cast<size_t>(-1)) ro.max_frames = last + 1;
		    source::replayRawlog(
		        inArg.getValue(), odo,
		        [&](const ego::FrameEgomotion& r,
		            const mrpt::obs::CObservation3DRangeScan& scan)
		        {
			        const size_t i = index++;
			        if (i < first || i > last) return;
			        if (r.flags & (ego::kFlagOutOfOrder | ego::kFlagBadImage))
				        return;
			        mrpt::poses::CPose3D T = r.T_WC;
			        if (!known.empty())
			        {
				        const StampedPose* p = poseNear(known, r.t, 5e-3);
				        if (!p)
				        {
					        ++noPose;
					        return;
				        }
				        T = p->T_WC;
			        }
			        ego::RgbdFrame f;
			        if (!ego::rgbdFrameFrom(scan, ec.camera, f).empty()) return;
			        frames.push_back(std::move(f));
			        poses.push_back(
			            T.getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>()
			                .asEigen());
		        },
		        ro);
		    if (frames.empty())
			    throw std::runtime_error(
			        inArg.getValue() +
			        ": no usable RGB-D frame in the range (check --frames, "
			        "[sensors] rgbd_label" +
			        std::string(known.empty() ? ")" : ", --poses stamps)"));
		    const ego::DepthFitResult res =
		        ego::estimateDepthCorrection(frames, poses);
		    std::printf(
		        "bims-calib-depth: %zu frames (%zu without a pose), %d pairs, "
		        "%zu residuals; robust RMS point-to-plane %.4f -> %.4f m\n"
		        "bims-calib-depth: correction (1 + delta): left %+.2f %%, "
		        "right "
		        "%+.2f %%, top %+.2f %%, bottom %+.2f %%, top-left corner "
		        "%+.2f %%\n",
		        frames.size(), noPose, res.pairs, res.residuals,
		        res.rms_before_m, res.rms_after_m, 100 * res.left,
		        100 * res.right, 100 * res.top, 100 * res.bottom,
		        100 * res.corner);
		    // A sensor's distortion is a few percent: a larger fit absorbed
		    // pose errors (a poor odometry, or moving objects in the stretch).
		    {
			    ego::DepthCorrection dc(res.params);
			    const ego::RgbdFrame& f0 = frames.front();
			    double worst = 0;
			    cv::Mat fac = dc.factors(f0.K, f0.depth.size());
			    cv::minMaxLoc(cv::abs(fac - 1), nullptr, &worst);
			    if (worst > maxArg.getValue())
			    {
				    char msg[400];
				    std::snprintf(
				        msg, sizeof(msg),
				        "the fitted correction reaches %.1f %% (limit "
				        "--max-correction %.1f %%): the %s do not fit a static "
				        "scene well enough; give --poses (e.g. ground truth) "
				        "or a "
				        "slower, longer static stretch (nothing written)",
				        100 * worst, 100 * maxArg.getValue(),
				        known.empty() ? "odometry's poses" : "given poses");
				    throw std::runtime_error(msg);
			    }
		    }
		    char note[512];
		    std::snprintf(
		        note, sizeof(note),
		        "# bims-calib-depth: %zu frames of %s (%s poses), "
		        "robust RMS %.4f -> %.4f m\n",
		        frames.size(),
		        mrpt::system::extractFileName(inArg.getValue()).c_str(),
		        known.empty() ? "vision odometry" : "given", res.rms_before_m,
		        res.rms_after_m);
		    bims::writeFileAtomically(outArg.getValue(),
		                              res.params.toIni(note));
		    return 0;
	    });
}
