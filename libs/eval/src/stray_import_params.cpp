#include <bims/common/experiment.h>
#include <bims/eval/rgbd_frame.h>
#include <bims/eval/stray_import.h>

namespace bims::eval
{
void StrayImportParams::describe(OptionVisitor& v)
{
	v.integer("min_confidence", min_confidence, 0, 2,
	          "depth readings whose ARKit confidence (0 low, 1 medium, 2 "
	          "high) is below this are written as 0 (no reading)");
	v.integer("colour_width", colour_width, 1, 100000,
	          "width of the colour stream camera_matrix.csv describes, "
	          "without rgb.mp4 to take it from [px]");
	v.integer("colour_height", colour_height, 1, 100000, "its height [px]");
}

void StrayImportParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg)
{
	checkExperimentSections(cfg);
	readOptions(*this, cfg, "import_stray");
	loadImportLabels(cfg, rgbd_label, imu_label);
	images.loadFromConfigFile(cfg, "input");
}

}  // namespace bims::eval
