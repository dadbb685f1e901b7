#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/eval/rgbd_frame.h>
#include <bims/eval/tum_import.h>

namespace bims::eval
{
void CameraIntrinsics::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	ConfigSection s(cfg, section);
	// as bims-run reads [camera]: the six together or none of them (none:
	// the defaults, TUM's camera), never some mixed with defaults
	std::string given, missing;
	for (const char* k : {"fx", "fy", "cx", "cy", "width", "height"})
		(s.has(k) ? given : missing) += std::string(" ") + k;
	if (!given.empty() && !missing.empty())
		s.fail(given.substr(1, given.find(' ', 1) - 1),
		       "fx fy cx cy width height: all or none; given:" + given +
		           ", missing:" + missing);
	width = static_cast<int>(s.getInt("width", width, 1, 100000));
	height = static_cast<int>(s.getInt("height", height, 1, 100000));
	fx = s.getDouble("fx", fx, 1e-3, 1e6);
	fy = s.getDouble("fy", fy, 1e-3, 1e6);
	cx = s.getDouble("cx", cx, -1e6, 1e6);
	cy = s.getDouble("cy", cy, -1e6, 1e6);
	depthScale = s.getDouble("depth_scale", depthScale, 1e-9, 1e9);
	if (depthScale < 1)
		s.fail(
		    "depth_scale",
		    "is the depth PNG value per metre (TUM, Bonn: 5000); a value below "
		    "1 looks like metres per unit (bims-sim's calibration.ini writes "
		    "that convention)");
	s.allow("max_range");  // read by other modules from the same section
	s.finish();
}

void ImportParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg)
{
	checkExperimentSections(cfg);
	camera.loadFromConfigFile(cfg, "camera");

	ConfigSection im(cfg, "import");
	maxTimeGap = im.getDouble("max_time_gap_s", maxTimeGap, 0.0, 10.0);
	bonnGt = im.getBool("bonn_gt", bonnGt);
	timestampFrom = im.getChoice("timestamp", timestampFrom);
	gtMaxGap = im.getDouble("gt_max_gap_s", gtMaxGap, 0.0, 60.0);
	rangeUnits = im.getDouble("range_units", rangeUnits, 1e-6, 0.1);
	accelLabel = im.getString("accel_label", accelLabel);
	if (accelLabel.empty()) im.fail("accel_label", "must not be empty");
	if (accelLabel.find("SYNTH") != std::string::npos)
		im.fail("accel_label",
		        "'" + accelLabel +
		            "': accelerometer.txt is a real sensor; a label with "
		            "SYNTH is the synthetic IMU's (--synth-imu)");
	im.finish();

	loadImportLabels(cfg, rgbdLabel, imuLabel);
	images.loadFromConfigFile(cfg, "input");
}

}  // namespace bims::eval
