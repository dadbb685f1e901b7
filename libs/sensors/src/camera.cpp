#include <bims/sensors/camera.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

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

std::string intrinsicsProblem(const PinholeCamera& c)
{
	char b[400];
	if (!(c.width > 0 && c.height > 0))
	{
		std::snprintf(b, sizeof(b), "an image of %dx%d pixels: not an image",
		              c.width, c.height);
		return b;
	}
	if (!(std::isfinite(c.fx) && std::isfinite(c.fy) && std::isfinite(c.cx) &&
	      std::isfinite(c.cy)))
		return "a value of fx fy cx cy is not a finite number";
	if (!(c.cx >= 0 && c.cx <= c.width && c.cy >= 0 && c.cy <= c.height))
	{
		std::snprintf(b, sizeof(b),
		              "the principal point (cx %g, cy %g) is outside the "
		              "%dx%d image (accepted: 0 <= cx <= %d, 0 <= cy <= %d): "
		              "intrinsics of another image size?",
		              c.cx, c.cy, c.width, c.height, c.width, c.height);
		return b;
	}
	constexpr double kPi = 3.14159265358979323846;
	const auto rad = [&](double deg) { return deg * kPi / 180; };
	for (const int axis : {0, 1})
	{
		const double f = axis == 0 ? c.fx : c.fy;
		const int n = axis == 0 ? c.width : c.height;
		// the focal lengths of the widest and the narrowest view accepted
		const double fLo = n / (2 * std::tan(rad(kMaxFieldOfViewDeg) / 2)),
		             fHi = n / (2 * std::tan(rad(kMinFieldOfViewDeg) / 2));
		if (f >= fLo && f <= fHi) continue;
		double fov = f > 0 ? 2 * std::atan(n / (2 * f)) * 180 / kPi : 180.0;
		if (fov < 1e-3) fov = 0;  // (said as 0, not 1.83e-296)
		std::snprintf(b, sizeof(b),
		              "%s %g gives a field of view of %.3g deg over the "
		              "image's %d pixels (accepted: %g to %g deg, i.e. %s from "
		              "%.4g to %.4g): intrinsics of another image size, or "
		              "not a camera's?",
		              axis == 0 ? "fx" : "fy", f, fov, n, kMinFieldOfViewDeg,
		              kMaxFieldOfViewDeg, axis == 0 ? "fx" : "fy", fLo, fHi);
		return b;
	}
	return "";
}

void checkIntrinsics(const PinholeCamera& c, const std::string& where)
{
	const std::string why = intrinsicsProblem(c);
	if (!why.empty()) throw std::runtime_error(where + ": " + why);
}

}  // namespace bims::sensors
