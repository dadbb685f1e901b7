// bims-flow-labels: optical-flow consistency labels for one RGB-D image pair.
//
//   bims-flow-labels RGB0.png RGB1.png DEPTH1.png -o OUTDIR [--config EXP.ini]
//       [--depth-scale 5000] [--fx F --fy F --cx C --cy C] [--pose "x y z yaw
//       pitch roll"]
//
// Computes the observed flow of frame 1 towards frame 0, the flow expected from
// frame 1's depth and the relative pose T_{C0 C1} (identity by default: a still
// camera), and the Diff/notDiff labels; writes colour pictures and prints
// per-stage timings. Useful to tune [flow] on real sensor data.
#include <bims/common/app.h>
#include <bims/common/clock.h>
#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/common/output_paths.h>
#include <bims/flow/consistency.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/observed_flow.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/filesystem.h>

#include <chrono>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace
{
cv::Mat readImage(const std::string& path, int flags)
{
	if (!mrpt::system::fileExists(path))
		throw std::runtime_error(path + ": no such file");
	cv::Mat m = cv::imread(path, flags);
	if (m.empty()) throw std::runtime_error(path + ": cannot decode image");
	return m;
}
}  // namespace

using bims::msSince;

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-flow-labels",
	    [&]()
	    {
		    TCLAP::CmdLine cmd(
		        "Optical-flow consistency labels (Diff/notDiff) for one RGB-D "
		        "pair",
		        ' ', bims::version());
		    TCLAP::UnlabeledValueArg<std::string> aRgb0(
		        "rgb0", "previous RGB image", true, "", "RGB0.png", cmd);
		    TCLAP::UnlabeledValueArg<std::string> aRgb1(
		        "rgb1", "current RGB image", true, "", "RGB1.png", cmd);
		    TCLAP::UnlabeledValueArg<std::string> aDepth1(
		        "depth1", "current depth (16-bit PNG)", true, "", "DEPTH1.png",
		        cmd);
		    TCLAP::ValueArg<std::string> aOut("o", "out", "output folder", true,
		                                      "", "OUTDIR", cmd);
		    TCLAP::ValueArg<std::string> aCfg(
		        "c", "config", "experiment .ini ([flow] section)", false, "",
		        "EXP.ini", cmd);
		    TCLAP::ValueArg<double> aScale("", "depth-scale",
		                                   "depth units per metre", false,
		                                   5000.0, "S", cmd);
		    TCLAP::ValueArg<double> aFx(
		        "", "fx", "focal x [px] (default 525 at 640 wide)", false, 0,
		        "F", cmd);
		    TCLAP::ValueArg<double> aFy("", "fy", "focal y [px]", false, 0, "F",
		                                cmd);
		    TCLAP::ValueArg<double> aCx("", "cx", "principal point x [px]",
		                                false, -1, "C", cmd);
		    TCLAP::ValueArg<double> aCy("", "cy", "principal point y [px]",
		                                false, -1, "C", cmd);
		    TCLAP::ValueArg<std::string> aPose(
		        "", "pose", "T_C0C1 as 'x y z yaw pitch roll' (m, deg)", false,
		        "0 0 0 0 0 0", "POSE", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    bims::checkOutputsSpareInputs({aRgb0.getValue(), aRgb1.getValue(),
		                                   aDepth1.getValue(), aCfg.getValue()},
		                                  {aOut.getValue()});

		    bims::flow::FlowParams params;
		    if (aCfg.isSet())
		    {
			    if (!mrpt::system::fileExists(aCfg.getValue()))
				    throw std::runtime_error(aCfg.getValue() +
				                             ": no such config file");
			    bims::checkIniFile(aCfg.getValue());
			    mrpt::config::CConfigFile cfg(aCfg.getValue());
			    bims::checkExperimentSections(cfg);
			    params.loadFromConfigFile(cfg, "flow");
		    }
		    const cv::Mat rgb0 = readImage(aRgb0.getValue(), cv::IMREAD_COLOR);
		    const cv::Mat rgb1 = readImage(aRgb1.getValue(), cv::IMREAD_COLOR);
		    const cv::Mat d16 =
		        readImage(aDepth1.getValue(), cv::IMREAD_UNCHANGED);
		    if (d16.type() != CV_16UC1)
			    throw std::runtime_error(
			        aDepth1.getValue() +
			        ": depth must be a 16-bit single-channel PNG");
		    if (rgb0.size() != rgb1.size() || rgb1.size() != d16.size())
			    throw std::runtime_error(
			        "images differ in size: " + aRgb0.getValue() + ", " +
			        aRgb1.getValue() + ", " + aDepth1.getValue());

		    mrpt::img::TCamera cam;
		    cam.ncols = rgb1.cols;
		    cam.nrows = rgb1.rows;
		    const double f = 525.0 * rgb1.cols / 640.0;
		    cam.setIntrinsicParamsFromValues(
		        aFx.getValue() > 0 ? aFx.getValue() : f,
		        aFy.getValue() > 0 ? aFy.getValue() : f,
		        aCx.getValue() >= 0 ? aCx.getValue() : rgb1.cols / 2.0,
		        aCy.getValue() >= 0 ? aCy.getValue() : rgb1.rows / 2.0);
		    double pv[6];
		    std::istringstream ps(aPose.getValue());
		    for (double& x : pv)
			    if (!(ps >> x))
				    throw bims::UsageError(
				        "--pose needs 6 numbers 'x y z yaw pitch roll'");
		    const mrpt::poses::CPose3D T_CprevC(
		        pv[0], pv[1], pv[2], mrpt::DEG2RAD(pv[3]), mrpt::DEG2RAD(pv[4]),
		        mrpt::DEG2RAD(pv[5]));

		    cv::Mat g0, g1, depth;
		    cv::cvtColor(rgb0, g0, cv::COLOR_BGR2GRAY);
		    cv::cvtColor(rgb1, g1, cv::COLOR_BGR2GRAY);
		    d16.convertTo(depth, CV_32FC1, 1.0 / aScale.getValue());

		    bims::flow::ObservedFlow of(params);
		    auto t0 = std::chrono::steady_clock::now();
		    const cv::Mat obs = of.compute(g0, g1);
		    const double tObs = msSince(t0);
		    t0 = std::chrono::steady_clock::now();
		    const cv::Mat exp =
		        bims::flow::expectedFlow(params.expected, depth, cam, T_CprevC);
		    const double tExp = msSince(t0);
		    t0 = std::chrono::steady_clock::now();
		    bims::flow::LabelStats st;
		    const cv::Mat lab = bims::flow::labelConsistency(
		        obs, exp, depth, cam, T_CprevC, params, &st);
		    const double tLab = msSince(t0);

		    const std::string out = aOut.getValue();
		    bims::makeDirs(out);
		    cv::Mat overlay = rgb1.clone();
		    for (int v = 0; v < lab.rows; v++)
			    for (int u = 0; u < lab.cols; u++)
				    if (lab.at<int8_t>(v, u) == bims::flow::kDiff)
					    overlay.at<cv::Vec3b>(v, u) =
					        overlay.at<cv::Vec3b>(v, u) / 2 +
					        cv::Vec3b(0, 0, 127);
		    bims::writeImageFile(out + "/observed_flow.png",
		                         bims::flow::flowToColor(obs, 10.0));
		    bims::writeImageFile(out + "/expected_flow.png",
		                         bims::flow::flowToColor(exp, 10.0));
		    bims::writeImageFile(out + "/labels.png",
		                         bims::flow::labelsToColor(lab));
		    bims::writeImageFile(out + "/overlay.png", overlay);
		    const size_t labelled = st.diff + st.notDiff;
		    std::printf(
		        "pixels %dx%d  labelled %zu  Diff %zu (%.2f %%)  notDiff %zu  "
		        "none %zu\n",
		        lab.cols, lab.rows, labelled, st.diff,
		        labelled ? 100.0 * st.diff / labelled : 0.0, st.notDiff,
		        st.none);
		    std::printf(
		        "ms: observed flow (%s) %.1f  expected flow %.1f  labels "
		        "%.1f\n",
		        bims::choiceName(params.method), tObs, tExp, tLab);
		    std::printf("pictures in %s/\n", out.c_str());
		    return 0;
	    });
}
