#include <bims/viewer/frame_view.h>

#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/stock_objects.h>

#include <sstream>
#include <stdexcept>

namespace bims::viewer
{
namespace
{
/** Each layer's --layers name and View-menu title, in Layer order. */
constexpr struct
{
	const char* name;
	const char* title;
} kLayers[kLayerCount] = {{"cloud", "Registered &cloud (moving points red)"},
                          {"tier0", "Tier &0 occupied voxels (faint blue)"},
                          {"tier1", "Tier &1 moving voxels (yellow)"},
                          {"tier2", "Tier &2 moving voxels (red)"},
                          {"trajectory", "&Estimated trajectory (cyan)"},
                          {"gt", "&Ground truth (green)"}};
}  // namespace

const char* layerName(Layer l)
{
	return kLayers[static_cast<size_t>(l)].name;
}

const char* layerTitle(Layer l)
{
	return kLayers[static_cast<size_t>(l)].title;
}

LayerVisibility LayerVisibility::parse(const std::string& list)
{
	LayerVisibility v;
	v.on.fill(false);
	std::stringstream s(list);
	std::string item;
	while (std::getline(s, item, ','))
	{
		if (item.empty() || item == "none") continue;
		if (item == "all")
		{
			v.on.fill(true);
			continue;
		}
		bool found = false;
		for (size_t i = 0; i < kLayerCount; ++i)
			if (item == layerName(static_cast<Layer>(i)))
				v.on[i] = found = true;
		if (!found)
		{
			std::string known;
			for (size_t i = 0; i < kLayerCount; ++i)
				known += std::string(i ? ", " : "") +
				         layerName(static_cast<Layer>(i));
			throw std::invalid_argument("unknown layer '" + item +
			                            "' (known: " + known + ", all, none)");
		}
	}
	return v;
}

const char* toString(Panel p)
{
	switch (p)
	{
		case Panel::RgbMask:
			return "RGB + moving mask";
		case Panel::Depth:
			return "Depth";
		case Panel::FlowObserved:
			return "Observed flow";
		case Panel::FlowExpected:
			return "Expected flow";
		case Panel::Labels:
			return "Diff labels";
	}
	return "?";
}

void showView(mrpt::opengl::COpenGLScene& scene, const FrameView& v,
              const LayerVisibility& visible)
{
	using namespace mrpt::opengl;
	scene.clear();
	auto vp = scene.getViewport();
	vp->setCustomBackgroundColor(mrpt::img::TColorf(0.12f, 0.12f, 0.14f));
	auto grid = CGridPlaneXY::Create(-5, 5, -5, 5, 0, 0.5);
	grid->setColor_u8(mrpt::img::TColor(90, 90, 90));
	scene.insert(grid);
	scene.insert(stock_objects::CornerXYZSimple(0.3f, 2.0f));
	for (size_t i = 0; i < kLayerCount; ++i)
		if (v.layers[i] && visible.on[i]) scene.insert(v.layers[i]);
	if (v.sensor) scene.insert(v.sensor);
}

}  // namespace bims::viewer
