// The bundled sample and the default experiment, as the tests find them in
// the source tree.
#pragma once

#include <string>

namespace bims::test
{
inline const std::string kSourceDir = BIMS_SOURCE_DIR;
/** rawlogs/pendulum_slow.rawlog, the bundled simulator sample. */
inline const std::string kSample = kSourceDir + "/rawlogs/pendulum_slow.rawlog";
/** Its ground truth folder (groundtruth.txt, calibration.ini, masks/). */
inline const std::string kSampleGt = kSourceDir + "/rawlogs/pendulum_slow_gt/";
/** config/default.ini. */
inline const std::string kDefaultConfig = kSourceDir + "/config/default.ini";
}  // namespace bims::test
