#include <bims/common/depth_image.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

namespace bims
{
DepthImage depthImageOf(const mrpt::obs::CObservation3DRangeScan& scan)
{
	DepthImage d;
	d.timestamp = scan.timestamp;
	d.label = scan.sensorLabel;
	d.units = scan.rangeUnits;
	d.isDepth = scan.range_is_depth;
	if (!scan.hasRangeImage) return d;
	const auto& img = scan.rangeImage;
	d.width = int(img.cols());
	d.height = int(img.rows());
	if (d.width > 0 && d.height > 0)
	{
		d.data = &img(0, 0);
		d.stride = d.height > 1 ? size_t(&img(1, 0) - &img(0, 0)) : img.cols();
	}
	return d;
}

}  // namespace bims
