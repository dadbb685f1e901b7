// How a library tells of what it skipped, assumed or found: a Warning handed
// to a callback (none: silent), never a line on a terminal of its own (the
// same rule as progress.h). The programs word and print them
// (bims/apps/warnings.h: "bims-run: warning: FILE: ...").
#pragma once

#include <functional>
#include <string>

namespace bims
{
/** One message of a library for the person running a program. */
struct Warning
{
	enum class Kind
	{
		Warning,  ///< something skipped or assumed: "warning: ..."
		Note,     ///< worth knowing, nothing wrong: "note: ..."
		Info,     ///< what the run uses (e.g. which IMU), no prefix
	};
	Kind kind = Kind::Warning;
	/** The input it is about (a file, a device, "input"); empty: none. */
	std::string where;
	/** What happened, one sentence without the program's name. */
	std::string text;
};

/** Receives a library's warnings; an empty one: nobody listens. */
using WarningCallback = std::function<void(const Warning&)>;

/** Hands \a w to \a cb when there is one. */
inline void reportWarning(const WarningCallback& cb, const Warning& w)
{
	if (cb) cb(w);
}

/** The program's warning callback: the one the libraries use where their
 * caller passed none (source::FrameOrderParams::warn, the maps' warnings).
 * Empty (silent) until the program sets it; bims::apps::runApp sets it to
 * the program's wording on stderr. */
const WarningCallback& programWarnings();
/** Sets programWarnings() (a program does so once, before its run). */
void setProgramWarnings(WarningCallback cb);

}  // namespace bims
