// How a long task of a library tells its progress: through a callback
// (none: silent), never a line on a terminal of its own. The programs'
// progress line, which they hand to the libraries as this callback:
// bims/apps/progress_bar.h.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

namespace bims
{
/** One report of a long task. A task reports {0, total} as it starts,
 * then as its steps get done, and once more with \a finished at its end
 * (not after an error). */
struct Progress
{
	size_t done = 0;   ///< steps done
	size_t total = 0;  ///< steps in all (0: unknown)
	/** \a total is an estimate (e.g. from the share of the input read). */
	bool estimated = false;
	bool finished = false;  ///< the last report: the task is over
	std::string note;       ///< about the last step, e.g. "frame 44"
};

/** Receives a task's progress; an empty one: nobody listens. */
using ProgressCallback = std::function<void(const Progress&)>;

/** Hands \a p to \a cb when there is one. */
inline void reportProgress(const ProgressCallback& cb, const Progress& p)
{
	if (cb) cb(p);
}

}  // namespace bims
