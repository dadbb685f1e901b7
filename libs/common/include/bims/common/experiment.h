// The sections of a bims experiment .ini (one file describes a whole run;
// see config/default.ini). Every program checks the file against this table
// so that a mistyped section is an error, and reads the sections it uses
// with ConfigSection (which rejects mistyped keys).
//
// One table for all programs, not a registry each module fills: one
// experiment file is shared by programs that do not link every module
// (bims-odom reads no [grids] but must accept them; [import_bag] stays valid
// in a build without ROS), so which sections a file may hold cannot depend
// on what a program links.
#pragma once

#include <mrpt/config/CConfigFileBase.h>

#include <string>
#include <vector>

namespace bims
{
/** One section of the experiment .ini: its name, the module or programs
 * that read it, and a title (docs/config.md's headings). */
struct ExperimentSection
{
	const char* name;
	const char* readBy;
	const char* title;
};

/** Every section, in file order. A module that adds a section adds it
 * here. Sections starting with "map" are MRPT map definitions
 * (CMultiMetricMap) and are also accepted. */
const std::vector<ExperimentSection>& experimentSectionTable();

/** The names of experimentSectionTable(). */
const std::vector<std::string>& experimentSections();

/** The entry of \a name; throws std::logic_error for a name not in the
 * table (a program's mistake, not a user's). */
const ExperimentSection& experimentSection(const std::string& name);

/** checkSections(cfg, experimentSections(), {"map"}). */
void checkExperimentSections(const mrpt::config::CConfigFileBase& cfg);

}  // namespace bims
