#include <bims/sensors/camera.h>

#include <cmath>
#include <sstream>

namespace bims::sensors
{
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

}  // namespace bims::sensors
