// bims's version.
#pragma once

namespace bims
{
/** bims's version (the CMake project's), for every program's --version. */
const char* version();

}  // namespace bims
