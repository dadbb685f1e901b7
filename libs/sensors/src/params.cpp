#include <bims/common/config.h>
#include <bims/common/so3.h>
#include <bims/sensors/params.h>

#include <Eigen/Core>

#include <sstream>

namespace bims::sensors
{
void CalibrationParams::describe(OptionVisitor& v)
{
	double r[9];
	for (int i = 0; i < 9; i++) r[i] = R_IC(i / 3, i % 3);
	v.reals("R_IC", r, 9, -1.0001, 1.0001,
	        "camera optical frame in the IMU frame, p_I = R_IC p_C (row "
	        "major); a file with [odometry] mode = imu must give it");
	const Eigen::Matrix3d M =
	    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r);
	const double err = (M * M.transpose() - Eigen::Matrix3d::Identity()).norm();
	std::ostringstream os;
	os << "not a rotation matrix (|R R^T - I| = " << err
	   << ", det = " << M.determinant() << ")";
	// re-orthonormalised, unless it is a rotation to double precision
	// already (so that an R_IC written out reads back the same)
	if (v.rule(err <= 1e-3 && M.determinant() >= 0, "R_IC", os.str()))
		R_IC = err <= 1e-12 ? M : orthonormalize(M);
	v.real("time_offset_s", time_offset_s, -10, 10,
	       "IMU stamp = camera stamp + this for the same instant [s]");
}

void CalibrationParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section,
    bool requireR)
{
	ConfigSection s(cfg, section);
	has_R_IC = s.has("R_IC");
	if (!has_R_IC && requireR)
		s.fail("R_IC",
		       "missing: the IMU-to-camera rotation (9 reals, row major, p_I = "
		       "R_IC p_C) is needed when [odometry] mode = imu");
	OptionReader r(s);
	describe(r);
	s.finish();
}

void CameraParams::describe(OptionVisitor& v)
{
	given = v.group({"fx", "fy", "cx", "cy", "width", "height"}, given);
	if (given)
	{
		v.real("fx", fx, 1, 1e5,
		       "focal length [px]; fx fy cx cy width height: all or none "
		       "(none: each observation's own intrinsics)");
		v.real("fy", fy, 1, 1e5, "focal length [px]");
		v.real("cx", cx, -1e5, 1e5, "principal point [px]");
		v.real("cy", cy, -1e5, 1e5, "principal point [px]");
		v.integer("width", width, 1, 100000, "image width [px]");
		v.integer("height", height, 1, 100000, "image height [px]");
	}
	// Keys bims-import-tum reads from the same section.
	for (const char* k : {"depth_scale", "max_range", "depth_units", "k1", "k2",
	                      "p1", "p2", "k3"})
		v.other(k);
}

void CameraParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section)
{
	readOptions(*this, cfg, section);
}

void SensorsParams::describe(OptionVisitor& v)
{
	v.text("rgbd_label", rgbd_label,
	       "sensor label of the 3D scans used (empty: any)");
	v.text("imu_label", imu_label,
	       "sensor label of the IMU observations used (empty: any)");
	v.other("rgbd_rate_hz");  // informative keys written by bims-sim
	v.other("imu_rate_hz");
}

void SensorsParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                       const std::string& section)
{
	readOptions(*this, cfg, section);
}

void DepthCorrectionParams::describe(OptionVisitor& v)
{
	v.flag("enable", enable, "correct the depth readings: z (1 + delta(x, y))");
	v.reals("coefficients", coefficients.data(), coefficients.size(), -10, 10,
	        "delta = sum c_i term_i(x, y); terms x y x^2 xy y^2 x^3 x^2y xy^2 "
	        "y^3 x^4 y^4 x^2y^2 (docs/ego.md)");
	v.other("fitted_on");  // informative keys written by bims-calib-depth
	v.other("rms_before_m");
	v.other("rms_after_m");
}

void DepthCorrectionParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	readOptions(*this, cfg, section);
}

std::string DepthCorrectionParams::toIni(const std::string& comment) const
{
	std::ostringstream os;
	os << "[depth_correction]\n";
	if (!comment.empty()) os << comment;
	os << "# z_true = z (1 + delta), delta = sum c_i term_i(x, y), x = (u - "
	      "cx) / fx, y = (v - cy) / fy;\n# terms: x y x^2 xy y^2 x^3 x^2y "
	      "xy^2 y^3 x^4 y^4 x^2y^2 (docs/ego.md)\n";
	os << "enable = " << (enable ? "true" : "false") << "\ncoefficients =";
	os.precision(9);
	for (double c : coefficients) os << " " << c;
	os << "\n";
	return os.str();
}

void SensorConfig::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                      bool requireR_IC)
{
	depth_correction.loadFromConfigFile(cfg);
	calibration.loadFromConfigFile(cfg, "calibration", requireR_IC);
	camera.loadFromConfigFile(cfg);
	sensors.loadFromConfigFile(cfg);
}

void SensorConfig::overrideSensorSections(
    const mrpt::config::CConfigFileBase& cal)
{
	if (cal.sectionExists("calibration")) calibration.loadFromConfigFile(cal);
	if (cal.sectionExists("camera")) camera.loadFromConfigFile(cal);
	if (cal.sectionExists("sensors")) sensors.loadFromConfigFile(cal);
	if (cal.sectionExists("depth_correction"))
		depth_correction.loadFromConfigFile(cal);
}

}  // namespace bims::sensors
