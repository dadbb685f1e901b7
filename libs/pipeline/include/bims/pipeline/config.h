// The whole experiment read from one .ini (see config/default.ini): the
// egomotion sections, [flow], [grids], [pipeline] and [output]. Unknown
// sections and keys are errors naming the file, the section and the key.
// The built-in defaults are config/default.ini's model; the configuration in
// use is written back as an .ini (effective.ini, bims-run --print-config)
// and the reference docs/config.md is generated from the same description.
#pragma once

#include <bims/common/choice.h>
#include <bims/common/options.h>
#include <bims/ego/params.h>
#include <bims/flow/params.h>
#include <bims/io/image_file.h>
#include <bims/maps/grid_params.h>
#include <bims/pipeline/surface_fill.h>

#include <mrpt/config/CConfigFileBase.h>

#include <optional>
#include <string>

namespace bims::pipeline
{
/** Which decision the output mask (and the tracker's feedback) uses
 * (bims-run --variant; the variants compared in docs/results.md). */
enum class Variant
{
	BottomOnly,   ///< tier-1 MAP (background subtraction)
	FlowOnly,     ///< the pixel's Diff label
	Fused,        ///< tier-2 MAP (the paper)
	FusedRaycast  ///< tier-2 MAP with decay = raycast
};
inline Choices<Variant> choices(Variant)
{
	static constexpr ChoiceName<Variant> t[] = {
	    {Variant::BottomOnly, "bottom-only"},
	    {Variant::FlowOnly, "flow-only"},
	    {Variant::Fused, "fused"},
	    {Variant::FusedRaycast, "fused-raycast"}};
	return t;
}
/** [pipeline] surface_fill: when a depth surface mostly called moving is
 * called moving whole (bims/pipeline/surface_fill.h). */
enum class SurfaceFill
{
	Off,
	/** Only on frames without the flow tier (depth only): the flow tier
	 * sees a surface's own motion, which the fill stands in for. */
	DepthOnly,
	Always
};

inline Choices<SurfaceFill> choices(SurfaceFill)
{
	static constexpr ChoiceName<SurfaceFill> t[] = {
	    {SurfaceFill::Off, "off"},
	    {SurfaceFill::DepthOnly, "depth-only"},
	    {SurfaceFill::Always, "always"}};
	return t;
}

/** Where a variant's moving mask comes from: the MAP of tier 1
 * (background subtraction) or tier 2 (flow consistency), or the flow labels
 * alone (no grid). */
enum class MaskSource
{
	FlowLabels,
	Tier1,
	Tier2
};

/** The variant's mask source (the one place that says it: the pipeline's
 * mask and exclude_moving tier, the outputs' static map). */
constexpr MaskSource maskSource(Variant v)
{
	return v == Variant::BottomOnly ? MaskSource::Tier1
	       : v == Variant::FlowOnly ? MaskSource::FlowLabels
	                                : MaskSource::Tier2;
}

/** [pipeline] */
struct PipelineParams
{
	Variant variant = Variant::Fused;
	/** The first frames only build the map: their masks are written empty
	 * (no background yet, no flow on frame 0). */
	int warmup_frames = 1;
	/** Feed the moving mask back to the tracker of the next frame. */
	bool feedback_mask = true;
	/** A camera frame waits at most this long (in data time) for IMU samples
	 * at its timestamp before it is processed anyway [s]. */
	double imu_wait_s = 0.1;
	/** bims-run reads and decodes the rawlogs ahead on a thread. */
	bool read_ahead = true;
	/** The observed flow (it needs only the images of t-1 and t) runs on a
	 * thread of its own while the egomotion runs; same results as in
	 * sequence. */
	bool flow_thread = true;
	/** With flow_thread: bims-run hands the pipeline the next frame when it
	 * is already read (and its IMU samples added), and that frame's observed
	 * flow runs on the flow thread while this frame's grids run; same
	 * results as without. */
	bool flow_lookahead = true;
	/** The FrameCloud of a frame (unprojection and voxel keys) is built on
	 * a thread of its own while the expected flow and the labels run; same
	 * results as without. */
	bool cloud_thread = true;
	/** Threads of OpenCV's own pool during a run (cv::setNumThreads; 1 = no
	 * pool, each call runs on the thread that makes it); 0 = OpenCV's
	 * default (one per core). */
	int opencv_threads = 0;
	/** When the variant's mask is filled over each depth surface mostly
	 * called moving (bims/pipeline/surface_fill.h). */
	SurfaceFill surface_fill = SurfaceFill::DepthOnly;
	/** surface_depth_jump, surface_min_moving, surface_max_area. */
	SurfaceFillParams surface;
	/** A frame whose pose was not measured against the static scene (the
	 * egomotion lost it, or the IMU's gate refused every alignment: the
	 * pose is a prediction) is held: not integrated into the grids, its
	 * mask empty (FrameResult::held). A pose nobody checked would paint the
	 * static scene where it is not, and call it moving. */
	bool hold_unregistered = true;

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "pipeline");
};

/** [output]: what bims-run writes besides trajectory, masks and metrics. */
struct OutputParams
{
	bool moving_ply = true;  ///< moving_voxels/NNNNNN.ply per frame
	bool static_map = true;  ///< static_map.ply and static_map.bt at the end
	bool labelled_rawlog = true;  ///< segmented.rawlog with pixel labels
	/** segmented.rawlog holds the input's images too (a whole copy: 2.9x the
	 * input on the Bonn slice); false: each 3D scan with its stamp, sensor
	 * label, camera and the labels only, read beside the input. */
	bool labelled_rawlog_images = false;
	/** gzip level of segmented.rawlog: 0 = plain (default: gzip costs more
	 * than the whole pipeline at 640x480), 1..9 = gzip. */
	int labelled_rawlog_gz_level = 0;
	bool flow_labels = false;  ///< flow_labels/NNNNNN.png (Diff red)
	/** Occupancy probability above which a voxel is in the static map. */
	double static_p_occupied = 0.7;
	/** Write the per-frame outputs on a background thread (in order; the
	 * run waits for them before it ends). */
	bool writer_thread = true;

	/** Every key of the section (bims/common/options.h). */
	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "output");
};

/** Everything one run reads. */
struct ExperimentConfig
{
	std::string source;  ///< file name ("<memory>" / "<defaults>")
	ego::EgoConfig ego;
	flow::FlowParams flow;
	maps::GridParams grids;
	PipelineParams pipeline;
	OutputParams output;
	/** [input]: the size limits of input image files (the importers',
	 * the labels' and masks' readers). */
	ImageLimits input;

	/** Reads every section (checkExperimentSections first). */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg);
	/** Opens and reads \a path; throws naming the file when missing. */
	void loadFromFile(const std::string& path);
	/** Reads .ini text with the same checks ("<memory>" in messages). */
	void loadFromText(const std::string& text);
	/** Applies a variant: sets pipeline.variant and, for fused-raycast,
	 * grids.decay = raycast. */
	void setVariant(Variant v);

	/** Every section and key with the value in use, as .ini text written
	 * with MRPT's config classes, each key's meaning as a comment:
	 * effective.ini of a run, bims-run --print-config. Read back, it gives
	 * this configuration again (R_IC included). */
	std::string effectiveIni() const;
	/** The same into \a out (sections of the experiment file). */
	void saveToConfigFile(mrpt::config::CConfigFileBase& out) const;
};

/** docs/config.md: every section and key of the experiment file with its
 * built-in default (config/default.ini's), its range or choices and its
 * meaning, from the same description as effectiveIni(). */
std::string configReference();

}  // namespace bims::pipeline
