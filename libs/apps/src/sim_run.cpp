#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>
#include <bims/apps/progress_bar.h>
#include <bims/apps/sim_run.h>
#include <bims/common/config.h>
#include <bims/io/output_paths.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/sim/imu.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/core/format.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace bims::apps
{
using sim::groundTruthLayout;
using sim::ImuParams;
using sim::ImuTruth;
using sim::SimConfig;
using sim::SimStats;

SimConfig simConfigFor(const SimOptions& o)
{
	auto cfg = SimConfig::load(o.scene.value_or(""));
	if (o.max_frames)
	{
		if (*o.max_frames < 1) throw UsageError("--max-frames must be >= 1");
		cfg.seq.frames = *o.max_frames;
	}
	if (o.resolution)
	{
		try
		{
			cfg.camera.setResolution(*o.resolution);
		}
		catch (const std::invalid_argument& e)
		{
			throw UsageError(e.what());
		}
	}
	if (o.preview && (*o.preview < 0 || *o.preview >= cfg.seq.frames))
		throw UsageError("--preview must be a frame index in [0, " +
		                 std::to_string(cfg.seq.frames - 1) + "]");
	return cfg;
}

std::string imuFromTum(const std::string& tum, const std::string& out,
                       uint64_t seed, const std::string& iniPath)
{
	ImuParams p;
	if (!iniPath.empty())
	{
		std::ifstream f(iniPath);
		if (!f) throw std::runtime_error(iniPath + ": cannot open IMU config");
		const auto ini = openIniFile(iniPath);
		checkSections(*ini, {"imu", "calibration"});
		p.loadFromConfigFile(*ini, "imu", "calibration");
	}
	const auto traj = loadTumTrajectory(tum);
	std::vector<ImuTruth> truth;
	const auto obs = synthesizeImu(traj, p, seed, &truth);
	PartialFile part(out);  // both renamed once complete
	PartialDir gt(groundTruthDirFor(out), groundTruthLayout());
	RawlogWriter w(part.path(), 1);
	for (const auto& o : obs) w.write(*o);
	w.close();
	saveImuTruth(gt.path() + "/imu.txt", truth);
	part.commit();
	gt.commit();
	const std::string& gtDir = gt.finalPath();
	return mrpt::format(
	    "bims-sim: %zu synthetic IMU samples (label %s) from %zu "
	    "poses -> %s, truth in %s/imu.txt\n",
	    obs.size(), obs.empty() ? "-" : obs.front()->sensorLabel.c_str(),
	    traj.size(), out.c_str(), gtDir.c_str());
}

std::string simSummary(const SimStats& st, const SimConfig& cfg)
{
	return mrpt::format(
	    "bims-sim: %zu frames %dx%d + %zu IMU samples in %.2f "
	    "s wall, %.2f s CPU "
	    "(%.1f frames/s wall, %.1f frames/s per CPU second, "
	    "render %.1f frames/s wall); "
	    "moving pixels %.1f %%; ground truth in %s\n",
	    st.frames, cfg.camera.width, cfg.camera.height, st.imuSamples,
	    st.seconds, st.cpuSeconds, st.frames / st.seconds,
	    st.frames / std::max(1e-9, st.cpuSeconds),
	    st.frames / std::max(1e-9, st.renderSeconds), 100 * st.movingFraction,
	    st.gtDir.c_str());
}

int runSim(const SimOptions& o)
{
	checkOutputsSpareInputs({o.scene.value_or(""), o.imu_from_tum.value_or(""),
	                         o.config.value_or("")},
	                        {o.out, groundTruthDirFor(o.out)});

	// after the checks, before any work: an earlier run's ground truth is
	// refused without --overwrite; with it, it is replaced only once the
	// new one is complete (PartialDir), so that it never mixes with this
	// one's (a shorter run would leave its extra masks)
	auto prepareGroundTruthDir = [&]
	{
		if (!o.overwrite)
			prepareOutputFolder(groundTruthDirFor(o.out), groundTruthLayout(),
			                    false);
	};
	if (o.imu_from_tum)
	{
		if (o.scene)
			throw UsageError("give either SCENE.ini or --imu-from-tum");
		prepareGroundTruthDir();
		std::fputs(
		    imuFromTum(*o.imu_from_tum, o.out, o.seed, o.config.value_or(""))
		        .c_str(),
		    stderr);
		return 0;
	}
	if (!o.scene) throw UsageError("missing SCENE.ini (or --imu-from-tum)");
	if (o.config) throw UsageError("--config only applies to --imu-from-tum");
	const SimConfig cfg = simConfigFor(o);
	prepareGroundTruthDir();
	ProgressBar bar("bims-sim", 0, o.progress);
	const auto st = runSimulation(cfg, o.out, o.seed, bar.callback(),
	                              o.preview.value_or(-1), o.stop);
	std::fputs(simSummary(st, cfg).c_str(), stderr);
	if (st.interrupted)
	{
		const int sig = stopSignal();
		std::fprintf(stderr,
		             "bims-sim: interrupted by %s after %zu of %d frames: "
		             "the rawlog and ground truth hold those frames, "
		             "complete\n",
		             sig == SIGTERM ? "SIGTERM" : "SIGINT", st.frames,
		             cfg.seq.frames);
		return 128 + (sig ? sig : SIGINT);
	}
	return 0;
}

}  // namespace bims::apps
