// The options every importer's run shares (bims-import-tum, -stray, -bag):
// the rawlog's gzip level and the optional experiment .ini.
#pragma once

#include <mrpt/config/CConfigFile.h>

#include <memory>
#include <optional>
#include <string>

namespace bims::apps
{
/** Throws UsageError "--gz must be in 0..9" unless \a gz is a gzip level. */
void checkGzLevel(int gz);

/** The experiment .ini \a config, opened as every program opens one
 * (bims::openIniFile); nullptr when none is given. Throws naming the file
 * when it does not exist ("FILE: config file not found"). */
std::unique_ptr<mrpt::config::CConfigFile> openImportConfig(
    const std::optional<std::string>& config);
}  // namespace bims::apps
