// What a file given on a command line is, by its content rather than its
// name: a rawlog, an .ini, a folder (a TUM RGB-D folder, a Stray Scanner
// capture), so that an input of the wrong kind, or two arguments swapped,
// is a usage error naming the command to use instead, before any output
// is created.
#pragma once

#include <string>
#include <vector>

namespace bims::apps
{
enum class InputKind
{
	Missing,      ///< no such path
	Folder,       ///< a folder of no kind below
	TumFolder,    ///< a TUM RGB-D / Bonn folder (rgb.txt or depth.txt)
	StrayFolder,  ///< a Stray Scanner capture (odometry.csv)
	IniText,      ///< text with a [section] line: an .ini
	Binary,       ///< a binary file (a rawlog, plain or gz-compressed)
	OtherText,    ///< text of no kind above
	Other         ///< not a regular file, or unreadable
};

/** The kind of \a path, from its first few kilobytes. */
InputKind inputKind(const std::string& path);

/** The command that reads a folder of \a kind ("bims-import-tum FOLDER -o
 * OUT.rawlog -c CONFIG.ini"), "" for other kinds. */
std::string importCommandFor(InputKind kind, const std::string& folder);

/** A rawlog input checked by kind: an .ini, a recording folder, another
 * folder or a text file is a UsageError naming the command to use instead
 * (\a usage: the program's own, "bims-info IN.rawlog"). A missing path is
 * left to the reader (its error names it). */
void checkRawlogInputKind(const std::string& path, const std::string& usage);

/** bims-run's inputs checked by kind: the experiment .ini and the rawlogs
 * swapped, a rawlog or a folder where the .ini belongs, an .ini or a
 * folder where a rawlog belongs. Throws UsageError naming the file and the
 * command to use instead. A config that does not exist as a path (a preset
 * named from share/bims) is left to the config's loader. */
void checkRunInputKinds(const std::string& config,
                        const std::vector<std::string>& rawlogs);

}  // namespace bims::apps
