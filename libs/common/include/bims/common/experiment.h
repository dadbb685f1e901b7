// The sections of a bims experiment .ini (one file describes a whole run;
// see config/default.ini). Every program checks the file against this list so
// that a mistyped section is an error, and reads the sections it uses with
// ConfigSection (which rejects mistyped keys).
#pragma once

#include <mrpt/config/CConfigFileBase.h>

#include <string>
#include <vector>

namespace bims
{
/** Section names every bims program accepts in an experiment .ini. A module
 * that adds a section adds its name here. Sections starting with "map" are
 * MRPT map definitions (CMultiMetricMap) and are also accepted. */
const std::vector<std::string>& experimentSections();

/** checkSections(cfg, experimentSections(), {"map"}). */
void checkExperimentSections(const mrpt::config::CConfigFileBase& cfg);

}  // namespace bims
