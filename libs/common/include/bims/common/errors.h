// Errors of the libraries: they throw plain errors (std::runtime_error,
// std::invalid_argument, bims::ConfigError of bims/common/config.h) naming
// what failed; the programs decide the exit code (bims/apps/app.h).
#pragma once

#include <string>

namespace bims
{
/** \a what on one line without MRPT's "==== MRPT exception ====" header and
 * its call stack backtrace (kept when the environment has BIMS_BACKTRACE). */
std::string withoutBacktrace(const std::string& what);

}  // namespace bims
