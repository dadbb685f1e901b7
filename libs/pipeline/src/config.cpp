#include <bims/common/config.h>
#include <bims/common/experiment.h>
#include <bims/common/share.h>
#include <bims/pipeline/config.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/system/filesystem.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace bims::pipeline
{
void PipelineParams::describe(OptionVisitor& v)
{
	v.choice("variant", variant,
	         "the decision of the output mask and of the tracker's feedback");
	v.integer("warmup_frames", warmup_frames, 0, 100000,
	          "the first frames only build the map (empty masks)");
	v.flag("feedback_mask", feedback_mask,
	       "feed the moving mask back to the tracker of the next frame");
	v.real("imu_wait_s", imu_wait_s, 0.0, 10.0,
	       "a camera frame waits at most this long (data time) for its IMU "
	       "samples [s]");
	v.flag("read_ahead", read_ahead, "read and decode the input on a thread");
	v.flag("flow_thread", flow_thread,
	       "the observed flow on a thread of its own (same results)");
	v.flag("flow_lookahead", flow_lookahead,
	       "and the next frame's observed flow during this frame's grids "
	       "(recordings; live input never waits for its next frame)");
	v.flag("cloud_thread", cloud_thread,
	       "the voxel cloud built on a thread beside the labels, and tier "
	       "0's decay of a frame on another during the next frame");
	v.integer("opencv_threads", opencv_threads, 0, 64,
	          "OpenCV's thread pool (0 = its default, 1 = none)");
	v.choice("surface_fill", surface_fill,
	         "when a depth surface mostly called moving is moving whole: "
	         "depth-only = on frames without the flow tier");
	v.real("surface_depth_jump", surface.depthJump, 0.001, 0.5,
	       "neighbouring pixels are on one surface when their depths differ "
	       "by less than this share of the larger");
	v.real("surface_min_moving", surface.minMoving, 0.01, 1.0,
	       "share of a surface's pixels called moving for all of it to be");
	v.real("surface_max_area", surface.maxArea, 0.0, 1.0,
	       "surfaces larger than this share of the image are never filled");
	v.real("surface_margin", surface.margin, 0.0, 10.0,
	       "a surface is filled only this far [m] from its moving pixels");
	v.real("surface_horizontal_deg", surface.horizontalDeg, 0.0, 89.0,
	       "with the IMU's gravity, pixels within this angle of horizontal "
	       "(floors) belong to no surface (0 = off)");
	v.flag("hold_unregistered", hold_unregistered,
	       "a frame whose pose was not measured against the static scene "
	       "(lost, or every alignment refused by the IMU) is not put into the "
	       "grids and its mask is empty");
}

void PipelineParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	readOptions(*this, cfg, section);
}

void OutputParams::describe(OptionVisitor& v)
{
	v.flag("moving_ply", moving_ply, "moving_voxels/NNNNNN.ply per frame");
	v.flag("static_map", static_map,
	       "static_map.ply and static_map.bt at the end");
	v.flag("labelled_rawlog", labelled_rawlog,
	       "segmented.rawlog with the masks as pixel labels");
	v.flag("labelled_rawlog_images", labelled_rawlog_images,
	       "segmented.rawlog copies the input's images too (false: each scan's "
	       "stamp, sensor label, camera and labels only)");
	v.integer("labelled_rawlog_gz_level", labelled_rawlog_gz_level, 0, 9,
	          "0 = plain, 1..9 = gzip");
	v.flag("flow_labels", flow_labels, "flow_labels/NNNNNN.png (Diff red)");
	v.real("static_p_occupied", static_p_occupied, 0.5, 0.999,
	       "occupancy probability above which a voxel is in the static map");
	v.flag("writer_thread", writer_thread,
	       "write the per-frame outputs on a thread");
}

void OutputParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section)
{
	readOptions(*this, cfg, section);
}

namespace
{
/** Every section bims-run reads with its options, in file order:
 * f(section, options); titles and readers: bims/common/experiment.h. */
template <typename Config, typename F>
void forEachSection(Config& c, F&& f)
{
	f("sensors", c.ego.sensors);
	f("calibration", c.ego.calibration);
	f("camera", c.ego.camera);
	f("depth_correction", c.ego.depth_correction);
	f("attitude", c.ego.attitude);
	f("tracker", c.ego.tracker);
	f("translation", c.ego.translation);
	f("odometry", c.ego.odometry);
	f("anchor", c.ego.anchor);
	f("inertial", c.ego.inertial);
	f("flow", c.flow);
	f("grids", c.grids);
	f("pipeline", c.pipeline);
	f("output", c.output);
	f("input", c.input);
}

/** A table cell: no line breaks, '|' escaped. */
std::string cell(const std::string& s)
{
	std::string o;
	for (char ch : s) o += ch == '|' ? std::string("\\|") : std::string(1, ch);
	return o;
}
}  // namespace

void ExperimentConfig::saveToConfigFile(
    mrpt::config::CConfigFileBase& out) const
{
	forEachSection(*this, [&](const char* section, const auto& opts)
	               { writeOptions(opts, out, section); });
}

std::string ExperimentConfig::effectiveIni() const
{
	mrpt::config::CConfigFileMemory mem;
	saveToConfigFile(mem);
	return "# bims: the parameters in use, every section and key "
	       "(docs/config.md)\n" +
	       mem.getContent();
}

std::string configReference()
{
	std::string md =
	    "# Configuration reference\n\n"
	    "Every section and key of an experiment `.ini` that `bims-run` "
	    "reads, with its\nbuilt-in default, its range or choices and its "
	    "meaning. Generated from the\noption structs' `describe()` "
	    "(`bims/common/options.h`), the source of\n`bims-run --print-config` "
	    "and of every run's `effective.ini` too: the test\n"
	    "`ConfigReference.DocsConfigMdIsUpToDate` fails when this file "
	    "differs.\n\n"
	    "The built-in defaults are the tuned model of `config/default.ini`; "
	    "`config/paper.ini`\nis the paper's literal model. An absent key "
	    "keeps its default, an unknown key\nor a value out of range is an "
	    "error naming the file, the section and the key.\n\n"
	    "| section | read by | what |\n|---|---|---|\n";
	for (const auto& s : experimentSectionTable())
		md += std::string("| `[") + s.name + "]` | " + s.readBy + " | " +
		      s.title + " |\n";
	md +=
	    "\nThe import sections (`docs/eval.md`, `docs/import-bag.md`), the "
	    "live node's\n`[ros2]` (`docs/ros2.md`) and MRPT map definitions "
	    "(`[map...]`) are not listed\nbelow.\n";
	const ExperimentConfig defaults;
	forEachSection(defaults,
	               [&](const char* section, const auto& opts)
	               {
		               md += std::string("\n## [") + section +
		                     "]: " + experimentSection(section).title +
		                     "\n\n| key | default | range | meaning |\n"
		                     "|---|---|---|---|\n";
		               for (const auto& r : optionRows(opts))
			               md += "| `" + r.key + "` | `" + cell(r.value) +
			                     "` | " + cell(r.range) + " | " + cell(r.doc) +
			                     " |\n";
	               });
	return md;
}

void ExperimentConfig::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg)
{
	source = configSourceName(cfg);
	checkExperimentSections(cfg);
	ego.loadFromConfigFile(cfg);
	flow.loadFromConfigFile(cfg, "flow");
	grids.loadFromConfigFile(cfg, "grids");
	pipeline.loadFromConfigFile(cfg, "pipeline");
	output.loadFromConfigFile(cfg, "output");
	input.loadFromConfigFile(cfg, "input");
	// import settings live in the same file (config/bonn.ini,
	// config/stray.ini, config/realsense.ini) but are read by the importers
	// only.
	if (pipeline.variant == Variant::FusedRaycast) setVariant(pipeline.variant);
}

void ExperimentConfig::loadFromFile(const std::string& given)
{
	const std::string path = resolvePreset(given);  // "bonn.ini": a preset
	if (!mrpt::system::fileExists(path))
		throw ConfigFileMissing(path + ": no such config file" +
		                        presetHint(path));
	loadFromConfigFile(*bims::openIniFile(path));
}

void ExperimentConfig::loadFromText(const std::string& text)
{
	checkIniText(text, "<memory>");
	mrpt::config::CConfigFileMemory mem(text);
	loadFromConfigFile(mem);
}

void ExperimentConfig::setVariant(Variant v)
{
	pipeline.variant = v;
	if (v == Variant::FusedRaycast) grids.decay = maps::DecayMode::Raycast;
}

}  // namespace bims::pipeline
