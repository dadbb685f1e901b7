// The one picture of a moving-pixel mask over a camera image: moving pixels
// blended half with red (the viewer, bims-grab's live preview,
// bims-flow-check's strip).
#pragma once

#include <opencv2/core.hpp>

namespace bims::pipeline
{
/** \a bgr (CV_8UC3; CV_8UC1 is taken as grey) with the pixels where \a mask
 * (CV_8UC1, non-zero = moving; resized to the image, nearest, when its size
 * differs) blended half with red. A copy; \a bgr alone when \a mask is
 * empty. */
cv::Mat overlayMoving(const cv::Mat& bgr, const cv::Mat& mask);

}  // namespace bims::pipeline
