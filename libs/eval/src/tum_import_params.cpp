#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/eval/rgbd_frame.h>
#include <bims/eval/tum_import.h>
#include <bims/sensors/params.h>

namespace bims::eval
{
void CameraIntrinsics::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	// the six as bims-run reads them (one rule: together or none of them,
	// the same ranges; none: the defaults, TUM's camera); the section's
	// unknown keys are refused there
	sensors::CameraParams given;
	given.loadFromConfigFile(cfg, section);
	if (given.given) static_cast<sensors::PinholeCamera&>(*this) = given;
	ConfigSection s(cfg, section);
	depthScale = s.getDouble("depth_scale", depthScale, 1e-9, 1e9);
	if (depthScale < 1)
		s.fail(
		    "depth_scale",
		    "is the depth PNG value per metre (TUM, Bonn: 5000); a value below "
		    "1 looks like metres per unit (bims-sim's calibration.ini writes "
		    "that convention)");
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
