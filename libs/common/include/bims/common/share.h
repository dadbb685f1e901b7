// The run-time files of share/bims (default and preset configs, README):
// found next to the running program, so that the build tree and any install
// prefix (moved or not) work the same way, then in the install prefix the
// build compiled in. See share/bims/README.md.
#pragma once

#include <string>

namespace bims
{
/** The folder of the running program (from /proc/self/exe, symbolic links
 * resolved); "" if it cannot be found. */
std::string executableDir();

/** share/bims of the install prefix the build was configured with
 * (CMAKE_INSTALL_FULL_DATADIR/bims), whether or not it exists. */
std::string installedShareDir();

/** The path of \a name (e.g. "default.ini", "sim/crowded.ini") inside
 * share/bims: first <exe dir>/../share/bims/NAME (the program's own tree:
 * build/bin -> build/share/bims, PREFIX/bin -> PREFIX/share/bims), then
 * installedShareDir()/NAME. Returns "" when neither is a file. */
std::string findShareFile(const std::string& name);

/** findShareFile() as if the program lived in \a exeDir (for tests). */
std::string findShareFile(const std::string& name, const std::string& exeDir);

/** A config file the user named: \a path itself when there is a file or
 * folder there; else, for a relative path, the preset of that name in
 * share/bims (findShareFile: "bonn.ini", "sim/crowded.ini") when there is
 * one; else \a path unchanged (its reader's error then names it, with
 * presetHint). */
std::string resolvePreset(const std::string& path);

/** What an error about a missing config file adds: " (nor a preset of that
 * name in DIR)" with the share/bims folder looked in, "" for an absolute
 * path. */
std::string presetHint(const std::string& path);

/** The experiment .ini of a program whose command line names none:
 * share/bims/default.ini, or "" (the built-in defaults of
 * pipeline::ExperimentConfig) when there is none. */
std::string defaultExperimentIni();

/** What a program prints about its parameters: "parameters from PATH", or
 * for an empty \a iniPath "parameters from built-in defaults (no
 * share/bims/default.ini found)". */
std::string parametersSource(const std::string& iniPath);
}  // namespace bims
