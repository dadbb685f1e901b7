#include <bims/viewer/frame_view.h>

#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/stock_objects.h>

#include <sstream>
#include <stdexcept>

namespace bims::viewer
{
const char* layerName(Layer l)
{
	switch (l)
	{
		case Layer::Cloud:
			return "cloud";
		case Layer::Tier0:
			return "tier0";
		case Layer::Tier1:
			return "tier1";
		case Layer::Tier2:
			return "tier2";
		case Layer::Estimated:
			return "trajectory";
		case Layer::GroundTruth:
			return "gt";
	}
	return "?";
}

const char* layerTitle(Layer l)
{
	switch (l)
	{
		case Layer::Cloud:
			return "Registered &cloud (moving points red)";
		case Layer::Tier0:
			return "Tier &0 occupied voxels (faint blue)";
		case Layer::Tier1:
			return "Tier &1 moving voxels (yellow)";
		case Layer::Tier2:
			return "Tier &2 moving voxels (red)";
		case Layer::Estimated:
			return "&Estimated trajectory (cyan)";
		case Layer::GroundTruth:
			return "&Ground truth (green)";
	}
	return "?";
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
