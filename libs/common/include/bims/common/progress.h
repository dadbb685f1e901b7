// A progress line for long runs, on stderr: "label [#####     ] 45/150 12.3/s".
// Redraws in place on a terminal, prints a plain line every ~10 % otherwise.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace bims
{
class ProgressBar
{
 public:
	/** \param total number of steps (0 = unknown). \param enabled false =
	 * silent. */
	ProgressBar(std::string label, size_t total, bool enabled = true);
	/** Sets the number of steps done; redraws at most every 0.2 s. */
	void update(size_t done, const std::string& extra = {});
	/** Final line with the total time. */
	void finish(const std::string& extra = {});

 private:
	void draw(size_t done, const std::string& extra, bool final);
	std::string label_;
	size_t total_;
	bool enabled_, tty_;
	size_t lastPct_ = 0;
	size_t lastDone_ = 0;
	std::chrono::steady_clock::time_point start_, last_;
	bool finished_ = false;
};

}  // namespace bims
