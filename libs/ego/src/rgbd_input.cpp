#include <bims/ego/rgbd_input.h>

#include <mrpt/core/Clock.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace bims::ego
{
std::string rgbdFrameFrom(const mrpt::obs::CObservation3DRangeScan& obs,
                          const CameraParams& cam, RgbdFrame& out)
{
	out.t = mrpt::Clock::toDouble(obs.timestamp);
	if (!obs.hasRangeImage || obs.rangeImage.rows() == 0)
		return "no range image";
	const_cast<mrpt::obs::CObservation3DRangeScan&>(obs).load();
	cv::Mat image;
	if (obs.hasIntensityImage && !obs.intensityImage.isEmpty())
		image = obs.intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY);
	Eigen::Matrix3d K;
	if (std::string why = sensors::intrinsicsOf(obs, cam, K); !why.empty())
		return why;
	return rgbdFrameFrom(depthImageOf(obs), image, K, out);
}

std::string rgbdFrameFrom(const DepthImage& depth, const cv::Mat& image,
                          const Eigen::Matrix3d& K, RgbdFrame& out)
{
	// Buffers shared with another frame (or not owned) are replaced, not
	// written into: a frame handed on keeps its images.
	for (cv::Mat* m : {&out.grey, &out.depth, &out.raw})
		if (!m->u || m->u->refcount > 1) m->release();
	out.stamp = depth.timestamp;
	if (depth.timestamp != mrpt::Clock::time_point{})
		out.t = mrpt::Clock::toDouble(depth.timestamp);
	if (depth.empty()) return "no range image";
	const int H = depth.height, W = depth.width;
	if (image.empty())
		out.grey.release();  // depth only
	else
	{
		if (image.channels() == 3)
			cv::cvtColor(image, out.grey, cv::COLOR_BGR2GRAY);
		else if (image.channels() == 1)
			out.grey = image;
		else
			return "intensity image has an unsupported channel count";
		if (out.grey.depth() != CV_8U) return "intensity image is not 8-bit";
		if (H != out.grey.rows || W != out.grey.cols)
		{
			std::ostringstream os;
			os << "depth " << W << "x" << H << " and intensity "
			   << out.grey.cols << "x" << out.grey.rows
			   << " differ (registered RGB-D expected)";
			return os.str();
		}
	}
	out.K = K;
	const float units = depth.units;
	if (!(units > 0) || !std::isfinite(units))
		return "invalid rangeUnits " + std::to_string(units) +
		       " (a finite value > 0 expected)";
	// The readings as read (what the voxel cloud is built from), and the
	// metric depth from them.
	cv::Mat(H, W, CV_16UC1, const_cast<uint16_t*>(depth.data),
	        depth.stride * sizeof(uint16_t))
	    .copyTo(out.raw);
	out.units = units;
	out.rangeIsDepth = depth.isDepth;
	out.depth.create(H, W, CV_32FC1);
	const double fx = K(0, 0), fy = K(1, 1), cx = K(0, 2), cy = K(1, 2);
	for (int v = 0; v < H; v++)
	{
		const uint16_t* in = out.raw.ptr<uint16_t>(v);
		float* row = out.depth.ptr<float>(v);
		for (int u = 0; u < W; u++)
		{
			float z = in[u] * units;
			if (!depth.isDepth && z > 0)
			{
				const double a = (u - cx) / fx, b = (v - cy) / fy;
				z = static_cast<float>(z / std::sqrt(1 + a * a + b * b));
			}
			row[u] = z;
		}
	}
	return {};
}

DepthImage RgbdFrame::rawDepth() const
{
	DepthImage d;
	if (raw.empty()) return d;
	d.data = raw.ptr<uint16_t>(0);
	d.width = raw.cols;
	d.height = raw.rows;
	d.stride = raw.step1();
	d.units = units;
	d.isDepth = rangeIsDepth;
	d.timestamp = stamp;
	return d;
}

float depthAt(const cv::Mat& depth, const cv::Point2f& x)
{
	const int u0 = static_cast<int>(std::floor(x.x));
	const int v0 = static_cast<int>(std::floor(x.y));
	if (u0 < 0 || v0 < 0 || u0 + 1 >= depth.cols || v0 + 1 >= depth.rows)
		return 0;
	const float a = depth.at<float>(v0, u0), b = depth.at<float>(v0, u0 + 1);
	const float c = depth.at<float>(v0 + 1, u0),
	            d = depth.at<float>(v0 + 1, u0 + 1);
	const float lo = std::min({a, b, c, d}), hi = std::max({a, b, c, d});
	if (!(lo > 0) || !std::isfinite(hi) || hi > 1.05f * lo) return 0;
	const float fu = x.x - u0, fv = x.y - v0;
	return (1 - fv) * ((1 - fu) * a + fu * b) + fv * ((1 - fu) * c + fu * d);
}

Eigen::Vector3d backProject(const Eigen::Matrix3d& K, const cv::Point2f& x,
                            double z)
{
	return {(x.x - K(0, 2)) / K(0, 0) * z, (x.y - K(1, 2)) / K(1, 1) * z, z};
}

}  // namespace bims::ego
