#include "rs_sdk.h"

#include <mrpt/core/format.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <stdexcept>

namespace bims::bag
{
BagTopics rsSdkTopics(const std::vector<BagTopicInfo>& topics)
{
	// /device_D/sensor_S/<Stream>_I/<image|imu>/data (ros_file_format.h)
	static const std::regex data(
	    "^((/device_[0-9]+/)sensor_[0-9]+/)(Depth|Color|Accel|Gyro)_[0-9]+/"
	    "(image|imu)/data$");
	auto has = [&](const std::string& name)
	{
		return std::any_of(topics.begin(), topics.end(),
		                   [&](const BagTopicInfo& t)
		                   { return t.name == name; });
	};
	// a stream's extrinsics: STREAM/tf/N, N its reference stream
	auto tfOf = [&](const std::string& stream)
	{
		for (const auto& t : topics)
			if (t.name.rfind(stream + "/tf/", 0) == 0) return t.name;
		return std::string();
	};
	BagTopics out;
	std::string device;
	// the first device's first stream of each kind (topics sorted by name)
	for (const char* want : {"Depth", "Color", "Accel", "Gyro"})
		for (const auto& t : topics)
		{
			std::smatch m;
			if (!std::regex_match(t.name, m, data) || m[3] != want) continue;
			const bool image = m[4] == "image";
			const std::string kind = m[3];
			if (image != (kind == "Depth" || kind == "Color")) continue;
			if (!device.empty() && m[2] != device) continue;
			// the stream's prefix: the topic without "/image/data"
			const std::string stream =
			    t.name.substr(0, t.name.size() - m[4].length() - 6);
			if (kind == "Depth")
			{
				device = m[2];
				out.depth = t.name;
				out.depthCameraInfo = stream + "/info/camera_info";
				out.depthTf = tfOf(stream);
				// the Depth Units option of the depth's sensor, as
				// librealsense names it ("Depth Units" before 2.50's
				// "Depth_Units")
				for (const char* o : {"Depth Units", "Depth_Units"})
					if (has(m[1].str() + "option/" + o + "/value"))
						out.depthUnits = m[1].str() + "option/" + o + "/value";
				if (out.depthUnits.empty())
					out.depthUnits = m[1].str() + "option/Depth Units/value";
			}
			else if (kind == "Color")
			{
				out.colour = t.name;
				out.cameraInfo = stream + "/info/camera_info";
				out.colourTf = tfOf(stream);
			}
			else if (kind == "Accel")
			{
				out.accel = t.name;
				out.accelTf = tfOf(stream);
			}
			else
			{
				out.gyro = t.name;
				out.gyroTf = tfOf(stream);
			}
			break;
		}
	if (out.depth.empty()) return BagTopics();
	if (out.colour.empty())
	{
		// the depth alone: its own camera is the frames'
		out.cameraInfo = out.depthCameraInfo;
		out.depthCameraInfo.clear();
	}
	return out;
}

RigidTransform rigidTransformOf(const TransformView& v)
{
	for (double x : {v.t[0], v.t[1], v.t[2], v.q[0], v.q[1], v.q[2], v.q[3]})
		if (!std::isfinite(x))
			throw std::runtime_error(mrpt::format(
			    "translation (%g %g %g), rotation (%g %g %g %g): not finite",
			    v.t[0], v.t[1], v.t[2], v.q[0], v.q[1], v.q[2], v.q[3]));
	const double n = std::sqrt(v.q[0] * v.q[0] + v.q[1] * v.q[1] +
	                           v.q[2] * v.q[2] + v.q[3] * v.q[3]);
	if (std::abs(n - 1) > 1e-3)
		throw std::runtime_error(mrpt::format(
		    "its rotation (%g %g %g %g) has norm %g: not a rotation", v.q[0],
		    v.q[1], v.q[2], v.q[3], n));
	const double x = v.q[0] / n, y = v.q[1] / n, z = v.q[2] / n, w = v.q[3] / n;
	RigidTransform r;
	const double R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),
	                     2 * (x * z + y * w),     2 * (x * y + z * w),
	                     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
	                     2 * (x * z - y * w),     2 * (y * z + x * w),
	                     1 - 2 * (x * x + y * y)};
	std::copy(R, R + 9, r.R);
	std::copy(v.t, v.t + 3, r.t);
	return r;
}

RigidTransform compose(const RigidTransform& b, const RigidTransform& a)
{
	RigidTransform c;
	for (int i = 0; i < 3; i++)
	{
		c.t[i] = b.t[i];
		for (int j = 0; j < 3; j++)
		{
			double s = 0;
			for (int k = 0; k < 3; k++) s += b.R[3 * i + k] * a.R[3 * k + j];
			c.R[3 * i + j] = s;
			c.t[i] += b.R[3 * i + j] * a.t[j];
		}
	}
	return c;
}

RigidTransform inverse(const RigidTransform& a)
{
	RigidTransform r;
	for (int i = 0; i < 3; i++)
	{
		r.t[i] = 0;
		for (int j = 0; j < 3; j++)
		{
			r.R[3 * i + j] = a.R[3 * j + i];
			r.t[i] -= a.R[3 * j + i] * a.t[j];
		}
	}
	return r;
}

double rotationDeg(const RigidTransform& a)
{
	const double c = std::clamp((a.R[0] + a.R[4] + a.R[8] - 1) / 2, -1.0, 1.0);
	return std::acos(c) * 180 / M_PI;
}

cv::Mat registerDepth(const cv::Mat& depth, double metresPerUnit,
                      const mrpt::img::TCamera& depthCam,
                      const mrpt::img::TCamera& colourCam,
                      const RigidTransform& T)
{
	const int W = static_cast<int>(colourCam.ncols),
	          H = static_cast<int>(colourCam.nrows);
	cv::Mat out(H, W, CV_32FC1, cv::Scalar(0));
	const double fxd = depthCam.fx(), fyd = depthCam.fy(), cxd = depthCam.cx(),
	             cyd = depthCam.cy();
	const double fxc = colourCam.fx(), fyc = colourCam.fy(),
	             cxc = colourCam.cx(), cyc = colourCam.cy();
	const double* R = T.R;
	const double* t = T.t;
	// the point of depth pixel (u, v) at depth z in the colour camera
	auto toColour = [&](double u, double v, double z, double p[3])
	{
		const double x = (u - cxd) / fxd * z, y = (v - cyd) / fyd * z;
		for (int i = 0; i < 3; i++)
			p[i] = R[3 * i] * x + R[3 * i + 1] * y + R[3 * i + 2] * z + t[i];
	};
	for (int v = 0; v < depth.rows; v++)
	{
		const uint16_t* row = depth.ptr<uint16_t>(v);
		for (int u = 0; u < depth.cols; u++)
		{
			if (row[u] == 0) continue;
			const double z = row[u] * metresPerUnit;
			double c[3], a[3], b[3];
			toColour(u, v, z, c);
			toColour(u - 0.5, v - 0.5, z, a);
			toColour(u + 0.5, v + 0.5, z, b);
			if (c[2] <= 0 || a[2] <= 0 || b[2] <= 0) continue;
			const double ua = fxc * a[0] / a[2] + cxc,
			             va = fyc * a[1] / a[2] + cyc,
			             ub = fxc * b[0] / b[2] + cxc,
			             vb = fyc * b[1] / b[2] + cyc;
			// the colour pixels whose centres the square covers
			const double u0 = std::max(std::ceil(std::min(ua, ub)), 0.0),
			             u1 = std::min(std::ceil(std::max(ua, ub)),
			                           static_cast<double>(W)),
			             v0 = std::max(std::ceil(std::min(va, vb)), 0.0),
			             v1 = std::min(std::ceil(std::max(va, vb)),
			                           static_cast<double>(H));
			const auto zc = static_cast<float>(c[2]);
			for (int r = static_cast<int>(v0); r < static_cast<int>(v1); r++)
			{
				float* o = out.ptr<float>(r);
				for (int k = static_cast<int>(u0); k < static_cast<int>(u1);
				     k++)
					if (o[k] == 0 || zc < o[k]) o[k] = zc;
			}
		}
	}
	return out;
}

}  // namespace bims::bag
