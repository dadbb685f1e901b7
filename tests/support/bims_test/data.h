// Where the tests find the shared real recordings (never copied into the
// repository; a test skips when its recording is not there).
#pragma once

#include <string>

namespace bims::test
{
/** The Bonn RGB-D Dynamic "crowd" frames 150-349 (their README). */
inline const std::string kBonnCrowd =
    std::string(BIMS_SHARED_DATA_DIR) + "/bonn_crowd_f150_349";
/** A Stray Scanner capture, frames 0-330, without its rgb.mp4 (their
 * README, section stray_early). */
inline const std::string kStrayEarly =
    std::string(BIMS_SHARED_DATA_DIR) + "/stray_early";
}  // namespace bims::test
