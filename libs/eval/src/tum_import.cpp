#include <bims/common/progress.h>
#include <bims/eval/pose_utils.h>
#include <bims/eval/rgbd_frame.h>
#include <bims/eval/tum_import.h>
#include <bims/io/image_file.h>
#include <bims/io/output_paths.h>
#include <bims/io/rawlog.h>
#include <bims/sensors/camera.h>

#include "import_rawlog.h"

#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/system/datetime.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

namespace bims::eval
{
namespace fs = std::filesystem;
using mrpt::obs::CObservation3DRangeScan;

mrpt::obs::CObservation3DRangeScan::Ptr loadDepthFrame(
    const std::string& depthPath, double t, const ImportParams& params)
{
	const auto& cam = params.camera;
	const cv::Mat raw = readDepthPng(depthPath, params.images);
	if (raw.cols != cam.width || raw.rows != cam.height)
		throw std::runtime_error(
		    depthPath + ": depth image is " + std::to_string(raw.cols) + "x" +
		    std::to_string(raw.rows) + " but [camera] says " +
		    std::to_string(cam.width) + "x" + std::to_string(cam.height));
	return depthObservation(raw, 1.0 / cam.depthScale, cam.tcamera(),
	                        params.rgbdLabel, t, params.rangeUnits);
}

mrpt::obs::CObservation3DRangeScan::Ptr loadFrame(const TumFrame& frame,
                                                  const ImportParams& params)
{
	const auto& cam = params.camera;
	auto o = loadDepthFrame(frame.depthPath, frame.t, params);
	const cv::Mat rgb = readImageFile(frame.rgbPath, cv::IMREAD_COLOR,
	                                  "colour image", params.images);
	if (rgb.cols != cam.width || rgb.rows != cam.height)
		throw std::runtime_error(
		    frame.rgbPath + ": colour image is " + std::to_string(rgb.cols) +
		    "x" + std::to_string(rgb.rows) + " but [camera] says " +
		    std::to_string(cam.width) + "x" + std::to_string(cam.height));
	attachColour(*o, rgb);
	return o;
}

std::vector<std::string> tumInputFiles(const TumFolder& tum)
{
	std::vector<std::string> files;
	for (const char* list :
	     {"rgb.txt", "depth.txt", "groundtruth.txt", "accelerometer.txt"})
		files.push_back(tum.path + "/" + list);
	for (const auto& f : tum.frames)
	{
		files.push_back(f.rgbPath);
		files.push_back(f.depthPath);
	}
	return files;
}

namespace
{
void writeCalibration(const std::string& path, const ImportParams& params)
{
	const auto& c = params.camera;
	char buf[512];
	std::snprintf(
	    buf, sizeof(buf),
	    "# Written by bims-import-tum: the camera of the imported rawlog.\n"
	    "[camera]\nfx = %.9g\nfy = %.9g\ncx = %.9g\ncy = %.9g\nwidth = %d\n"
	    "height = %d\ndepth_scale = %.9g\n\n[sensors]\nrgbd_label = %s\n"
	    "imu_label = %s\n",
	    c.fx, c.fy, c.cx, c.cy, c.width, c.height, c.depthScale,
	    params.rgbdLabel.c_str(), params.imuLabel.c_str());
	writeFileAtomically(path, buf);
}
}  // namespace

ImportSummary importTum(const std::string& folder, const std::string& outRawlog,
                        const ImportParams& params,
                        const ImportOptions& options)
{
	return importTum(readTumFolder(folder, params), outRawlog, params, options);
}

namespace
{
/** The ground truth of the import: T_WC of the optical frame at each
 * frame's stamp (interpolated; the frames without one counted), written to
 * \a gtFile. */
void writeTumGroundTruth(const TumFolder& tum, const ImportParams& params,
                         const ImportOptions& options,
                         const std::string& gtFile, ImportSummary& sum)
{
	const std::string& folder = tum.path;
	Trajectory gt = tum.groundTruth;
	if (options.bonnGt || params.bonnGt)
		for (auto& p : gt) p.T_WC = bonnMarkerToCamera(p.T_WC);
	for (const auto& f : tum.frames)
	{
		const auto T = interpolatePose(gt, f.t, params.gtMaxGap);
		if (T)
			sum.groundTruth.push_back({f.t, *T});
		else
			sum.framesWithoutGt++;
	}
	sum.gtPoses = sum.groundTruth.size();
	saveTumTrajectory(
	    gtFile, sum.groundTruth,
	    std::string("T_WC of the camera optical frame at each 3D scan's "
	                "stamp, from ") +
	        folder + "/groundtruth.txt" +
	        ((options.bonnGt || params.bonnGt)
	             ? " (Bonn marker-to-camera conversion applied)"
	             : ""));
}
}  // namespace

ImportSummary importTum(TumFolder tum, const std::string& outRawlog,
                        const ImportParams& params,
                        const ImportOptions& options)
{
	// the intrinsics can be a camera of the images they are given for
	sensors::checkIntrinsics(params.camera, "[camera] of the import");
	if (options.maxFrames > 0 && tum.frames.size() > options.maxFrames)
		tum.frames.resize(options.maxFrames);
	const double t0 = tum.frames.front().t, t1 = tum.frames.back().t;

	ImportSummary sum;
	sum.gtDir = groundTruthDirFor(outRawlog);
	// OUT_gt.partial/ until the rawlog is complete: a failed import leaves
	// the earlier rawlog and its ground truth as they were
	static const OutputFolderLayout gtLayout{
	    {"calibration.ini", "groundtruth.txt"}, {}};
	PartialDir gtPart(sum.gtDir, gtLayout);
	writeCalibration(gtPart.path() + "/calibration.ini", params);

	// Ground truth: T_WC of the optical frame at each frame's stamp.
	if (tum.hasGroundTruth)
		writeTumGroundTruth(tum, params, options,
		                    gtPart.path() + "/groundtruth.txt", sum);

	// Merge frames and IMU by time: (t, kind, index); kind 0 = IMU first at
	// equal stamps (kind 0 accel file, 1 extra, 2 frame).
	std::vector<TimedInput> items;
	for (size_t i = 0; i < tum.accel.size(); i++)
		if (tum.accel[i].t >= t0 && tum.accel[i].t <= t1)
			items.push_back({tum.accel[i].t, 0, i});
	for (size_t i = 0; i < options.extra.size(); i++)
	{
		const double t = mrpt::Clock::toDouble(options.extra[i]->timestamp);
		if (t >= t0 && t <= t1) items.push_back({t, 1, i});
	}
	for (size_t i = 0; i < tum.frames.size(); i++)
		items.push_back({tum.frames[i].t, 2, i});
	sortByTime(items);

	ImportRawlog out(outRawlog, options.gzLevel, tum.frames.size(),
	                 options.progress);
	RawlogWriter& w = out.w;
	for (const auto& it : items)
	{
		if (it.kind == 2)
		{
			w.write(*loadFrame(tum.frames[it.i], params));
			out.frameWritten(++sum.frames);
		}
		else if (it.kind == 1)
		{
			w.write(*options.extra[it.i]);
			if (sum.imu++ == 0) sum.imuLabel = options.extra[it.i]->sensorLabel;
		}
		else
		{
			const auto& a = tum.accel[it.i];
			const auto m =
			    imuObservation(params.accelLabel, a.t, nullptr, a.a, nullptr);
			w.write(*m);
			sum.accel++;
		}
	}
	w.close();
	out.part.commit();
	gtPart.commit();
	out.finished();
	return sum;
}

}  // namespace bims::eval
