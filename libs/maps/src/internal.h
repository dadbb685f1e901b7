// Private helpers of the maps library.
#pragma once

#include <string>
#include <vector>

namespace bims::maps
{
/** Generic MRPT keys accepted in a map's creationOpts section. */
const std::vector<std::string>& mrptGenericMapKeys();
}  // namespace bims::maps
