// The output rules of the programs that throw usage errors (exit code 2):
// outputs never alias inputs, an output folder holding an earlier run is
// refused unless --overwrite. The rest of the rule, for every library
// (partial files, append-only files): bims/io/output_paths.h.
#pragma once

#include <bims/io/output_paths.h>

#include <string>
#include <vector>

namespace bims
{
/** Refuses, before any work, outputs that would destroy an input: an empty
 * output path, an output that is an input, or an output folder that
 * contains an input. Paths are compared after resolving symbolic links, `.`
 * and `..` (std::filesystem::weakly_canonical), so a link or a relative
 * path to an input is the input. \a inputs: every file and folder the
 * program reads: also the files an input folder holds that it reads (a TUM
 * folder's lists and images, the masks of a mask folder: frameFilesIn)
 * and the files its .ini files name; empty strings (optional arguments not
 * given) are ignored. Throws UsageError naming both paths. */
void checkOutputsSpareInputs(const std::vector<std::string>& inputs,
                             const std::vector<std::string>& outputs);

/** Before a program writes into the folder \a dir: when \a dir holds files
 * of \a layout or a manifest (an earlier run), throws UsageError naming the
 * folder and one of them, and suggesting \a overwriteFlag. With
 * \a overwrite, removes what the earlier run's manifest lists (OutputManifest,
 * bims/io/output_paths.h: removeListedOutputs) and returns how many
 * files it removed; a file of \a layout the manifest does not list (no
 * manifest: any) is kept and refused (UsageError naming it), before
 * anything is removed. A symbolic link at an output name (a per-frame
 * sub-folder too) is refused (naming it) or, with \a overwrite, removed:
 * what it points to is never followed nor emptied. The program then starts
 * its own OutputManifest. */
size_t prepareOutputFolder(const std::string& dir,
                           const OutputFolderLayout& layout, bool overwrite,
                           const std::string& overwriteFlag = "--overwrite");

}  // namespace bims
