// One frame as the viewer draws it: built once on the replay thread from
// the pipeline's state, then only read by the GUI thread, which never
// touches the pipeline (docs/viewer.md, "Threads").
#pragma once

#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CRenderizable.h>

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

namespace bims::viewer
{
/** The 3D view's layers, in the order of the View menu. */
enum class Layer
{
	Cloud,       ///< current frame's registered cloud, moving points red
	Tier0,       ///< occupied voxels (faint blue points; off by default)
	Tier1,       ///< tier-1 moving voxels, yellow cubes
	Tier2,       ///< tier-2 moving voxels, red cubes
	Estimated,   ///< estimated trajectory, cyan
	GroundTruth  ///< ground-truth trajectory, green
};
constexpr size_t kLayerCount = 6;
/** "cloud", "tier0", "tier1", "tier2", "trajectory", "gt" (--layers). */
const char* layerName(Layer l);
/** The View menu's text of a layer. */
const char* layerTitle(Layer l);

/** Which layers the 3D view shows. By default everything but the static
 * tier-0 voxels, which would hide what moves. */
struct LayerVisibility
{
	std::array<bool, kLayerCount> on{true, false, true, true, true, true};
	bool& operator[](Layer l) { return on[static_cast<size_t>(l)]; }
	bool operator[](Layer l) const { return on[static_cast<size_t>(l)]; }
	/** From "cloud,tier1,gt" (layerName()s; "all", "none"); throws
	 * std::invalid_argument naming an unknown one and listing the known. */
	static LayerVisibility parse(const std::string& list);
};

/** The 2D panels. */
enum class Panel
{
	RgbMask,       ///< intensity image with the moving mask in red
	Depth,         ///< depth, jet colour map
	FlowObserved,  ///< observed backward flow (HSV code)
	FlowExpected,  ///< expected backward flow from depth + egomotion
	Labels         ///< flow labels: Diff red, notDiff green
};
constexpr size_t kPanelCount = 5;
const char* toString(Panel p);

/** An orbit camera of the 3D view (MRPT's CCamera parameters). */
struct ViewCamera
{
	float pointX = 0, pointY = 0, pointZ = 0;  ///< look-at point in {W} [m]
	float zoom = 5;                            ///< distance [m]
	float azimuthDeg = -135, elevationDeg = 30;
};

/** Everything the GUI draws of one frame. Immutable once built. */
struct FrameView
{
	uint64_t seq = 0;  ///< publication number (ReplayWorker; 0 = direct)
	long frame = -1;   ///< timeline position (-1: before the first frame)
	size_t frameCount = 0;
	/** The moving mask shown (CV_8UC1, 255 = moving; may be empty). */
	cv::Mat mask;
	/** The 2D panels as BGR (CV_8UC3), in Panel order. */
	std::array<cv::Mat, kPanelCount> panels;
	/** The 3D layers in Layer order; null where hidden when built or with
	 * nothing to show. */
	std::array<mrpt::opengl::CRenderizable::Ptr, kLayerCount> layers;
	mrpt::opengl::CRenderizable::Ptr sensor;  ///< the sensor's axes at T_WC
	ViewCamera follow;                        ///< behind-above the sensor
	std::string counter;                      ///< "12 / 149": the frame counter
	std::string status;  ///< the status line (starts with the counter's)

	const cv::Mat& panel(Panel p) const
	{
		return panels[static_cast<size_t>(p)];
	}
	const mrpt::opengl::CRenderizable::Ptr& layer(Layer l) const
	{
		return layers[static_cast<size_t>(l)];
	}
};

/** Replaces the scene's content with the floor grid, the axes of {W}, the
 * visible layers of \a v and the sensor's axes. Cheap: the objects are
 * shared, not copied. */
void showView(mrpt::opengl::COpenGLScene& scene, const FrameView& v,
              const LayerVisibility& visible);

}  // namespace bims::viewer
