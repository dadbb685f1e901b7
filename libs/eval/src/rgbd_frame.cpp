#include <bims/common/config.h>
#include <bims/eval/rgbd_frame.h>
#include <bims/io/image_file.h>
#include <mrpt/core/Clock.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

namespace bims::eval
{
using mrpt::obs::CObservation3DRangeScan;

cv::Mat readDepthPng(const std::string& path, const ImageLimits& limits)
{
	cv::Mat raw =
	    readImageFile(path, cv::IMREAD_UNCHANGED, "depth image", limits);
	if (raw.type() != CV_16UC1)
		throw std::runtime_error(path +
		                         ": depth must be a 16-bit single-channel PNG");
	return raw;
}

CObservation3DRangeScan::Ptr depthObservation(const cv::Mat& depth,
                                              double metresPerUnit,
                                              const mrpt::img::TCamera& camera,
                                              const std::string& label,
                                              double t, double rangeUnits)
{
	const int W = static_cast<int>(camera.ncols),
	          H = static_cast<int>(camera.nrows);
	const bool metric = depth.type() == CV_32FC1;
	if ((depth.type() != CV_16UC1 && !metric) || depth.cols != W ||
	    depth.rows != H)
		throw std::invalid_argument(
		    "depthObservation: a CV_16UC1 or CV_32FC1 image of the camera's "
		    "size " +
		    std::to_string(W) + "x" + std::to_string(H) + " expected");
	auto o = CObservation3DRangeScan::Create();
	o->sensorLabel = label;
	o->timestamp = mrpt::Clock::fromDouble(t);
	o->sensorPose = mrpt::poses::CPose3D();
	o->hasRangeImage = true;
	o->range_is_depth = true;
	o->rangeUnits = static_cast<float>(rangeUnits);
	o->maxRange = static_cast<float>(65535 * rangeUnits);
	o->stdError = 0.01f;
	o->rangeImage_setSize(H, W);
	const double k = metresPerUnit / rangeUnits;
	auto toUnits = [&](double value)
	{
		// no reading: 0, negative, NaN, infinite or beyond the range image
		const double units = std::round(value * k);
		return units > 0 && units <= 65535 ? static_cast<uint16_t>(units)
		                                   : uint16_t(0);
	};
	for (int v = 0; v < H; v++)
	{
		if (metric)
		{
			const float* r = depth.ptr<float>(v);
			for (int u = 0; u < W; u++) o->rangeImage(v, u) = toUnits(r[u]);
		}
		else
		{
			const uint16_t* r = depth.ptr<uint16_t>(v);
			for (int u = 0; u < W; u++) o->rangeImage(v, u) = toUnits(r[u]);
		}
	}
	o->cameraParams = camera;
	o->cameraParamsIntensity = camera;
	return o;
}

void attachColour(CObservation3DRangeScan& obs, const cv::Mat& bgr)
{
	if (bgr.type() != CV_8UC3 ||
	    bgr.cols != static_cast<int>(obs.rangeImage.cols()) ||
	    bgr.rows != static_cast<int>(obs.rangeImage.rows()))
		throw std::invalid_argument(
		    "attachColour: an 8-bit BGR image of the depth image's size "
		    "expected");
	// the intensity camera is the depth camera (registered RGB-D): the pose
	// only turns MRPT's 3D-scan axes into the optical axes
	obs.relativePoseIntensityWRTDepth =
	    mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
	obs.hasIntensityImage = true;
	obs.intensityImageChannel = CObservation3DRangeScan::CH_VISIBLE;
	obs.intensityImage = mrpt::img::CImage(bgr, mrpt::img::DEEP_COPY);
}

mrpt::obs::CObservationIMU::Ptr imuObservation(const std::string& label,
                                               double t, const double* gyro,
                                               const double* accel,
                                               const double* mag)
{
	using namespace mrpt::obs;
	auto m = CObservationIMU::Create();
	m->sensorLabel = label;
	m->timestamp = mrpt::Clock::fromDouble(t);
	auto put =
	    [&](const double* v, TIMUDataIndex x, TIMUDataIndex y, TIMUDataIndex z)
	{
		if (!v) return;
		m->set(x, v[0]);
		m->set(y, v[1]);
		m->set(z, v[2]);
	};
	put(gyro, IMU_WX, IMU_WY, IMU_WZ);
	put(accel, IMU_X_ACC, IMU_Y_ACC, IMU_Z_ACC);
	put(mag, IMU_MAG_X, IMU_MAG_Y, IMU_MAG_Z);
	return m;
}

void loadImportLabels(const mrpt::config::CConfigFileBase& cfg,
                      std::string& rgbdLabel, std::string& imuLabel)
{
	ConfigSection se(cfg, "sensors");
	// Empty means "any label" to the readers of a rawlog; the importer
	// then writes the label given.
	const std::string r = se.getString("rgbd_label", rgbdLabel);
	const std::string i = se.getString("imu_label", imuLabel);
	// Informative keys of bims-sim's OUT_gt/calibration.ini.
	se.allow("rgbd_rate_hz");
	se.allow("imu_rate_hz");
	if (!r.empty()) rgbdLabel = r;
	if (!i.empty()) imuLabel = i;
	se.finish();
}

}  // namespace bims::eval
