// The progress line of a long command, on stderr (one implementation for
// every program; -q turns it off). The libraries report their progress
// through a bims::ProgressCallback (bims/common/progress.h): a program hands
// them its bar's callback().
//   on a terminal, one line redrawn in place at most every 0.2 s:
//     "bims-run [#####      ] 45/150 frames 30 % 12.3/s ETA 8.5 s frame 44"
//   otherwise (a log file, a pipe), a plain line at every tenth of the total
//   and at least every kLineEverySeconds, never a carriage return:
//     "bims-run: 45/150 frames (30 %), 12.3 frames/s, 3.7 s, ETA 8.5 s"
// A total that is an estimate (e.g. from the share of the input read)
// prints as "~150"; without a total, the count and the rate alone.
#pragma once

#include <bims/common/progress.h>

#include <chrono>
#include <cstddef>
#include <string>

namespace bims
{
/** "8.5 s", "3 min 05 s", "1 h 02 min". */
std::string formatDuration(double seconds);

class ProgressBar
{
 public:
	/** Seconds between two plain lines at most (not on a terminal). */
	static constexpr double kLineEverySeconds = 5.0;

	/** \param total number of steps (0 = unknown). \param enabled false =
	 * silent (-q). \param unit what a step is ("frames"). */
	ProgressBar(std::string label, size_t total, bool enabled = true,
	            std::string unit = "frames");
	/** Sets the total (e.g. once known or estimated); \a estimated prints it
	 * as "~N". */
	void setTotal(size_t total, bool estimated = false);
	/** Sets the number of steps done and draws when due. */
	void update(size_t done, const std::string& extra = {});
	/** Final line with the total time. */
	void finish(const std::string& extra = {});

	/** What a library reports to: each report sets the total and draws as
	 * update() (with its note), or finish() at the last one; the clock
	 * starts at the first report (the task's start, not the bar's). Empty
	 * when the bar is off (-q): the library then reports to nobody. The
	 * bar must outlive the task. */
	ProgressCallback callback();
	/** One report (what callback() calls). */
	void report(const Progress& p);

	/** The text of one line (without "\r" or the end of line): \a done of
	 * the total after \a seconds, as drawn on a terminal (\a tty) or as a
	 * plain line. For tests. */
	std::string text(size_t done, double seconds, bool tty,
	                 const std::string& extra = {}) const;

 private:
	void draw(size_t done, const std::string& extra, bool final);
	std::string label_, unit_;
	size_t total_;
	bool estimated_ = false;
	bool enabled_, tty_;
	size_t lastTenth_ = 0;
	size_t lastDone_ = 0;
	std::chrono::steady_clock::time_point start_, last_;
	bool finished_ = false;
	bool reported_ = false;  ///< a report came: the clock runs
};

}  // namespace bims
