#include <bims/common/input_file.h>
#include <bims/eval/association.h>
#include <bims/eval/rgbd_frame.h>
#include <bims/eval/tum_import.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>

namespace bims::eval
{
namespace fs = std::filesystem;

namespace
{
struct StampedFile
{
	double t;
	std::string path;
};

bool skipLine(const std::string& line)
{
	const auto p = line.find_first_not_of(" \t\r");
	return p == std::string::npos || line[p] == '#';
}

/** rgb.txt / depth.txt: "timestamp filename" per line. */
std::vector<StampedFile> readFileList(const fs::path& listPath)
{
	if (inputFileProblem(listPath.string()) == "no such file")
		throw std::runtime_error(listPath.string() +
		                         ": cannot open (is this a TUM RGB-D folder?)");
	LineReader f(listPath.string(), "file list");
	std::vector<StampedFile> out;
	std::string line;
	while (f.next(line))
	{
		const size_t n = f.lineNumber();
		if (skipLine(line)) continue;
		std::istringstream ss(line);
		StampedFile e;
		if (!(ss >> e.t >> e.path) || !std::isfinite(e.t))
			throw std::runtime_error(listPath.string() + ":" +
			                         std::to_string(n) +
			                         ": expected 'timestamp filename'");
		if (!out.empty() && e.t < out.back().t)
			throw std::runtime_error(listPath.string() + ":" +
			                         std::to_string(n) +
			                         ": timestamp goes backwards");
		e.path = (listPath.parent_path() / e.path).string();
		out.push_back(e);
	}
	if (out.empty())
		throw std::runtime_error(listPath.string() + ": no entries");
	return out;
}

std::vector<AccelSample> readAccel(const fs::path& p)
{
	LineReader f(p.string(), "accelerometer file");
	std::vector<AccelSample> out;
	std::string line;
	while (f.next(line))
	{
		const size_t n = f.lineNumber();
		if (skipLine(line)) continue;
		std::istringstream ss(line);
		AccelSample a;
		if (!(ss >> a.t >> a.a[0] >> a.a[1] >> a.a[2]) || !std::isfinite(a.t) ||
		    !std::isfinite(a.a[0]) || !std::isfinite(a.a[1]) ||
		    !std::isfinite(a.a[2]))
			throw std::runtime_error(p.string() + ":" + std::to_string(n) +
			                         ": expected 'timestamp ax ay az'");
		if (!out.empty() && a.t < out.back().t)
			throw std::runtime_error(p.string() + ":" + std::to_string(n) +
			                         ": timestamp goes backwards");
		out.push_back(a);
	}
	return out;
}
}  // namespace

TumFolder readTumFolder(const std::string& folder, const ImportParams& params)
{
	const fs::path dir(folder);
	if (!fs::is_directory(dir))
		throw std::runtime_error(folder + ": not a directory");
	TumFolder out;
	out.path = folder;
	const auto rgb = readFileList(dir / "rgb.txt");
	const auto depth = readFileList(dir / "depth.txt");
	out.rgbCount = rgb.size();
	out.depthCount = depth.size();

	std::vector<double> tr, td;
	for (const auto& e : rgb) tr.push_back(e.t);
	for (const auto& e : depth) td.push_back(e.t);
	const auto pairs = associateGreedy(tr, td, params.maxTimeGap);
	if (pairs.empty())
		throw std::runtime_error(folder + ": no RGB and depth images within " +
		                         std::to_string(params.maxTimeGap) +
		                         " s of each other ([import] max_time_gap_s)");
	for (const auto& [i, j] : pairs)
	{
		TumFrame f;
		f.tRgb = rgb[i].t;
		f.tDepth = depth[j].t;
		f.t = params.timestampFrom == TimestampSource::Rgb ? f.tRgb : f.tDepth;
		f.rgbPath = rgb[i].path;
		f.depthPath = depth[j].path;
		out.frames.push_back(f);
	}
	std::stable_sort(out.frames.begin(), out.frames.end(),
	                 [](const TumFrame& a, const TumFrame& b)
	                 { return a.t < b.t; });

	if (fs::exists(dir / "accelerometer.txt"))
		out.accel = readAccel(dir / "accelerometer.txt");
	if (fs::exists(dir / "groundtruth.txt"))
	{
		out.groundTruth = loadTumTrajectory((dir / "groundtruth.txt").string());
		if (out.groundTruth.empty())
			throw std::runtime_error((dir / "groundtruth.txt").string() +
			                         ": no poses");
		out.hasGroundTruth = true;
	}
	return out;
}

cv::Mat loadDepthMeters(const std::string& path, const CameraIntrinsics& cam)
{
	// the camera's size: a file declaring more is refused before decoding
	const cv::Mat raw = readDepthPng(
	    path, ImageLimits{std::max<long>(cam.width, cam.height),
	                      static_cast<long>(cam.width) * cam.height,
	                      "[camera]'s size"});
	if (raw.cols != cam.width || raw.rows != cam.height)
		throw std::runtime_error(
		    path + ": depth image is " + std::to_string(raw.cols) + "x" +
		    std::to_string(raw.rows) + " but [camera] says " +
		    std::to_string(cam.width) + "x" + std::to_string(cam.height));
	cv::Mat m;
	raw.convertTo(m, CV_32F, 1.0 / cam.depthScale);
	return m;
}

}  // namespace bims::eval
