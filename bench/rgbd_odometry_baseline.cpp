// The baseline of docs/journal/egomotion.md "Egomotion in a crowd": OpenCV
// contrib's frame-to-frame dense odometry (cv::rgbd::RgbdICPOdometry, or its
// ICP / photometric variants) on the RGB-D frames of a rawlog, with OpenCV's
// defaults, written as a TUM trajectory.
//
//   rgbd_odometry_baseline CONFIG.ini IN.rawlog -o TRAJ.txt
//       [--method rgbdicp|icp|rgbd] [--no-depth-correction]
//
// CONFIG's [camera] and [sensors] select the frames, as for bims-odom; its
// [depth_correction] is applied (as bims applies it) unless
// --no-depth-correction. Prints the median and p95 ms per frame of compute().
#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/ego/depth_correction.h>
#include <bims/ego/odometry.h>
#include <bims/ego/rgbd_input.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/pipeline/run.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <opencv2/rgbd.hpp>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

int main(int argc, char** argv)
{
	std::string cfgPath, in, out, method = "rgbdicp";
	bool correct = true;
	for (int i = 1; i < argc; i++)
	{
		const std::string a = argv[i];
		if (a == "-o" && i + 1 < argc)
			out = argv[++i];
		else if (a == "--method" && i + 1 < argc)
			method = argv[++i];
		else if (a == "--no-depth-correction")
			correct = false;
		else if (cfgPath.empty())
			cfgPath = a;
		else if (in.empty())
			in = a;
		else
		{
			std::fprintf(stderr, "unexpected argument '%s'\n", a.c_str());
			return 2;
		}
	}
	if (cfgPath.empty() || in.empty() || out.empty() ||
	    (method != "rgbdicp" && method != "icp" && method != "rgbd"))
	{
		std::fprintf(stderr,
		             "usage: %s CONFIG.ini IN.rawlog -o TRAJ.txt [--method "
		             "rgbdicp|icp|rgbd] [--no-depth-correction]\n",
		             argv[0]);
		return 2;
	}
	try
	{
		mrpt::config::CConfigFile cfg(cfgPath);
		bims::checkExperimentSections(cfg);
		bims::ego::EgoConfig ec;
		ec.loadFromConfigFile(cfg, false);
		bims::sensors::DepthCorrection dc(ec.depth_correction);
		bims::RawlogReader reader(in);
		cv::Ptr<cv::rgbd::Odometry> odo;
		bims::Trajectory traj;
		std::vector<double> ms;
		cv::Mat prevGrey, prevDepth, T_WC = cv::Mat::eye(4, 4, CV_64F);
		size_t failed = 0;
		while (auto o = reader.next())
		{
			auto scan =
			    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
			        o);
			if (!scan || (!ec.sensors.rgbd_label.empty() &&
			              scan->sensorLabel != ec.sensors.rgbd_label))
				continue;
			if (correct) dc.apply(*scan, ec.camera);
			bims::ego::RgbdFrame f;
			const std::string why =
			    bims::ego::rgbdFrameFrom(*scan, ec.camera, f);
			if (!why.empty()) throw std::runtime_error(in + ": " + why);
			if (!odo)
			{
				cv::Mat K(3, 3, CV_32F);
				for (int r = 0; r < 3; r++)
					for (int c = 0; c < 3; c++)
						K.at<float>(r, c) = static_cast<float>(f.K(r, c));
				if (method == "icp")
					odo = cv::rgbd::ICPOdometry::create(K);
				else if (method == "rgbd")
					odo = cv::rgbd::RgbdOdometry::create(K);
				else
					odo = cv::rgbd::RgbdICPOdometry::create(K);
			}
			cv::Mat depth = f.depth.clone();
			depth.setTo(std::numeric_limits<float>::quiet_NaN(), depth == 0);
			if (!prevGrey.empty())
			{
				// dst_p = Rt src_p with src = this frame, dst = the previous
				// one: Rt = T_CprevC
				cv::Mat Rt;
				const auto t0 = std::chrono::steady_clock::now();
				const bool ok = odo->compute(f.grey, depth, cv::Mat(), prevGrey,
				                             prevDepth, cv::Mat(), Rt);
				ms.push_back(std::chrono::duration<double, std::milli>(
				                 std::chrono::steady_clock::now() - t0)
				                 .count());
				if (ok)
					T_WC = T_WC * Rt;
				else
					++failed;  // keeps the last pose (no motion)
			}
			Eigen::Matrix3d R;
			Eigen::Vector3d t;
			for (int r = 0; r < 3; r++)
			{
				t[r] = T_WC.at<double>(r, 3);
				for (int c = 0; c < 3; c++) R(r, c) = T_WC.at<double>(r, c);
			}
			traj.push_back({f.t, bims::ego::toPose(R, t)});
			prevGrey = f.grey.clone();
			prevDepth = depth;
		}
		bims::saveTumTrajectory(out, traj,
		                        "OpenCV cv::rgbd " + method + " odometry");
		const auto pc = bims::pipeline::Percentiles::of(ms);
		std::printf(
		    "rgbd_odometry_baseline: %zu frames, %zu failed, ms/frame median "
		    "%.2f p95 %.2f (method %s, depth correction %s)\n",
		    traj.size(), failed, pc.median, pc.p95, method.c_str(),
		    correct && dc.enabled() ? "on" : "off");
		return 0;
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "rgbd_odometry_baseline: error: %s\n", e.what());
		return 1;
	}
}
