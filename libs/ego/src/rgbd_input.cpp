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
	const int H = static_cast<int>(obs.rangeImage.rows());
	const int W = static_cast<int>(obs.rangeImage.cols());
	if (!obs.hasIntensityImage || obs.intensityImage.isEmpty())
		out.grey.release();  // depth only
	else
	{
		cv::Mat img =
		    obs.intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY);
		if (img.channels() == 3)
			cv::cvtColor(img, out.grey, cv::COLOR_BGR2GRAY);
		else if (img.channels() == 1)
			out.grey = img;
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
	if (std::string why = intrinsicsOf(obs, cam, out.K); !why.empty())
		return why;
	const float units = obs.rangeUnits;
	if (!(units > 0) || !std::isfinite(units))
		return "invalid rangeUnits " + std::to_string(units) +
		       " (a finite value > 0 expected)";
	out.depth.create(H, W, CV_32FC1);
	const double fx = out.K(0, 0), fy = out.K(1, 1), cx = out.K(0, 2),
	             cy = out.K(1, 2);
	for (int v = 0; v < H; v++)
	{
		float* row = out.depth.ptr<float>(v);
		for (int u = 0; u < W; u++)
		{
			float z = obs.rangeImage(v, u) * units;
			if (!obs.range_is_depth && z > 0)
			{
				const double a = (u - cx) / fx, b = (v - cy) / fy;
				z = static_cast<float>(z / std::sqrt(1 + a * a + b * b));
			}
			row[u] = z;
		}
	}
	return {};
}

mrpt::img::TCamera RgbdFrame::camera() const
{
	mrpt::img::TCamera c;
	c.ncols = static_cast<uint32_t>(depth.cols);
	c.nrows = static_cast<uint32_t>(depth.rows);
	c.setIntrinsicParamsFromValues(K(0, 0), K(1, 1), K(0, 2), K(1, 2));
	return c;
}

std::string intrinsicsOf(const mrpt::obs::CObservation3DRangeScan& obs,
                         const CameraParams& cam, Eigen::Matrix3d& K)
{
	const int H = static_cast<int>(obs.rangeImage.rows());
	const int W = static_cast<int>(obs.rangeImage.cols());
	if (cam.given)
	{
		if (cam.width != W || cam.height != H)
		{
			std::ostringstream os;
			os << "[camera] says " << cam.width << "x" << cam.height
			   << " but the images are " << W << "x" << H;
			return os.str();
		}
		K << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1;
		return {};
	}
	const auto& cp = obs.cameraParams;
	// NaN fails every comparison: require finite, positive focal lengths
	if (!(cp.fx() > 0) || !(cp.fy() > 0) || !std::isfinite(cp.fx()) ||
	    !std::isfinite(cp.fy()) || !std::isfinite(cp.cx()) ||
	    !std::isfinite(cp.cy()))
	{
		std::ostringstream os;
		os << "invalid cameraParams (fx " << cp.fx() << ", fy " << cp.fy()
		   << ", cx " << cp.cx() << ", cy " << cp.cy()
		   << "; finite values and fx, fy > 0 expected)";
		return os.str();
	}
	K << cp.fx(), 0, cp.cx(), 0, cp.fy(), cp.cy(), 0, 0, 1;
	return {};
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
