// A textured image for tests of dense flow.
#pragma once

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>

namespace bims::test
{
/** A \a cols x \a rows BGR image of smooth grey blobs that dense flow can
 * follow, its pattern moved \a shift pixels to the right. */
inline cv::Mat flowTexture(int cols, int rows, int shift)
{
	cv::Mat m(rows, cols, CV_8UC3);
	for (int v = 0; v < rows; v++)
		for (int u = 0; u < cols; u++)
		{
			const double x = u - shift;
			const auto g =
			    static_cast<uint8_t>(128 + 60 * std::sin(x * 0.21) +
			                         60 * std::cos(v * 0.17 + x * 0.05));
			m.at<cv::Vec3b>(v, u) = cv::Vec3b(g, g, g);
		}
	return m;
}
}  // namespace bims::test
