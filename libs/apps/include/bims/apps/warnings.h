// The programs' wording of the libraries' warnings (bims/common/warnings.h):
// one line on stderr each, "PROGRAM: warning: WHERE: TEXT" (a note:
// "PROGRAM: note: WHERE: TEXT"; what the run uses: "PROGRAM: WHERE: TEXT").
// runApp makes this the program's warning callback (bims::programWarnings).
#pragma once

#include <bims/common/warnings.h>

#include <string>

namespace bims
{
/** \a w as the line \a program prints for it (with its newline). */
std::string wordWarning(const std::string& program, const Warning& w);

/** A callback printing each warning as wordWarning() on stderr. */
WarningCallback stderrWarnings(const std::string& program);

}  // namespace bims
