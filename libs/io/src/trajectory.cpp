#include <bims/common/input_file.h>
#include <bims/io/output_paths.h>
#include <bims/io/trajectory.h>
#include <mrpt/poses/CPose3DQuat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bims
{
Trajectory loadTumTrajectory(const std::string& path)
{
	if (inputFileProblem(path) == "no such file")
		throw std::runtime_error(path + ": cannot open trajectory file");
	LineReader f(path, "trajectory file");
	Trajectory out;
	std::string line;
	while (f.next(line))
	{
		const size_t lineNo = f.lineNumber();
		const auto p = line.find_first_not_of(" \t\r");
		if (p == std::string::npos || line[p] == '#') continue;
		std::istringstream ss(line);
		double v[8];
		for (double& x : v)
			if (!(ss >> x) || !std::isfinite(x))
				throw std::runtime_error(path + ":" + std::to_string(lineNo) +
				                         ": expected 8 finite numbers "
				                         "'timestamp tx ty tz qx qy qz qw'");
		const double qn =
		    std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
		if (std::abs(qn - 1.0) > 1e-3)
			throw std::runtime_error(path + ":" + std::to_string(lineNo) +
			                         ": quaternion is not unit (norm " +
			                         std::to_string(qn) + ")");
		if (!out.empty() && v[0] < out.back().t)
			throw std::runtime_error(path + ":" + std::to_string(lineNo) +
			                         ": timestamp goes backwards");
		mrpt::math::CQuaternionDouble q(v[7] / qn, v[4] / qn, v[5] / qn,
		                                v[6] / qn);
		out.push_back({v[0], mrpt::poses::CPose3D(mrpt::poses::CPose3DQuat(
		                         v[1], v[2], v[3], q))});
	}
	return out;
}

std::string tumLine(double t, const mrpt::poses::CPose3D& T_WC)
{
	const mrpt::poses::CPose3DQuat q(T_WC);
	char buf[256];
	std::snprintf(buf, sizeof(buf), "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f",
	              t, q.x(), q.y(), q.z(), q.quat().x(), q.quat().y(),
	              q.quat().z(), q.quat().r());
	return buf;
}

std::string tumHeader(const std::string& comment)
{
	return (comment.empty() ? std::string() : "# " + comment + "\n") +
	       "# timestamp tx ty tz qx qy qz qw\n";
}

void saveTumTrajectory(const std::string& path, const Trajectory& traj,
                       const std::string& headerComment)
{
	writeFileAtomically(path, tumTrajectoryText(path, traj, headerComment));
}

std::string tumTrajectoryText(const std::string& path, const Trajectory& traj,
                              const std::string& headerComment)
{
	std::string text = tumHeader(headerComment);
	for (const auto& p : traj)
	{
		const std::string line = tumLine(p.t, p.T_WC);
		// a NaN pose is a failure upstream, never a trajectory line
		if (line.find("nan") != std::string::npos ||
		    line.find("inf") != std::string::npos)
			throw std::runtime_error(path + ": the pose at t " +
			                         std::to_string(p.t) + " is not finite (" +
			                         line + "); nothing written");
		text += line + "\n";
	}
	return text;
}

const StampedPose* poseNear(const Trajectory& traj, double t, double maxDt)
{
	auto it = std::lower_bound(traj.begin(), traj.end(), t,
	                           [](const StampedPose& p, double v)
	                           { return p.t < v; });
	const StampedPose* best = nullptr;
	double bestDt = maxDt;
	for (auto j : {it, it == traj.begin() ? it : it - 1})
		if (j != traj.end() && std::abs(j->t - t) < bestDt)
		{
			best = &*j;
			bestDt = std::abs(j->t - t);
		}
	return best;
}

}  // namespace bims
