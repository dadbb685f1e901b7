// What the recording importers (tum_import.cpp, stray_import.cpp) share:
// their inputs merged in time order, and the rawlog they write
// (OUT.rawlog.partial until complete, its progress counted in frames).
#pragma once

#include <bims/common/progress.h>
#include <bims/io/output_paths.h>
#include <bims/io/rawlog.h>

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

namespace bims::eval
{
/** One input of an import: its stamp [s], its kind (at equal stamps the
 * lower kind first: the IMU before the frames) and its index among the
 * inputs of its kind. */
struct TimedInput
{
	double t;
	int kind;
	size_t i;
};

/** Sorts \a items by stamp, the lower kind first at equal stamps, in their
 * given order otherwise. */
inline void sortByTime(std::vector<TimedInput>& items)
{
	std::stable_sort(items.begin(), items.end(),
	                 [](const TimedInput& a, const TimedInput& b)
	                 { return a.t < b.t || (a.t == b.t && a.kind < b.kind); });
}

/** The rawlog an import writes: OUT.rawlog.partial until committed (a
 * failed import leaves no half-written rawlog under the final name), and
 * its progress in frames ({0, frames} reported at once). */
struct ImportRawlog
{
	ImportRawlog(const std::string& outRawlog, int gzLevel, size_t frames,
	             const ProgressCallback& cb)
	    : part(outRawlog), w(part.path(), gzLevel), cb_(cb)
	{
		progress.total = frames;
		reportProgress(cb_, progress);
	}
	/** A frame written: \a done of them so far. */
	void frameWritten(size_t done)
	{
		progress.done = done;
		reportProgress(cb_, progress);
	}
	/** The import is over (its outputs committed). */
	void finished()
	{
		progress.finished = true;
		reportProgress(cb_, progress);
	}

	PartialFile part;
	RawlogWriter w;
	Progress progress;

 private:
	const ProgressCallback& cb_;
};

}  // namespace bims::eval
