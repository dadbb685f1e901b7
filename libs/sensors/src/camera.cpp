#include <bims/sensors/camera.h>

#include <cmath>
#include <sstream>

namespace bims::sensors
{
Eigen::Matrix3d PinholeCamera::K() const
{
	Eigen::Matrix3d k;
	k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
	return k;
}

PinholeCamera PinholeCamera::fromK(const Eigen::Matrix3d& K, int width,
                                   int height)
{
	return {width, height, K(0, 0), K(1, 1), K(0, 2), K(1, 2)};
}

mrpt::img::TCamera PinholeCamera::tcamera() const
{
	mrpt::img::TCamera c;
	c.ncols = static_cast<uint32_t>(width);
	c.nrows = static_cast<uint32_t>(height);
	c.setIntrinsicParamsFromValues(fx, fy, cx, cy);
	c.distortion = mrpt::img::DistortionModel::none;
	return c;
}

PinholeCamera PinholeCamera::of(const mrpt::img::TCamera& c)
{
	return {static_cast<int>(c.ncols),
	        static_cast<int>(c.nrows),
	        c.fx(),
	        c.fy(),
	        c.cx(),
	        c.cy()};
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
		K = cam.K();
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

}  // namespace bims::sensors
