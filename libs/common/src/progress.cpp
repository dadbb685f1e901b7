#include <bims/common/progress.h>
#include <unistd.h>

#include <cstdio>

namespace bims
{
ProgressBar::ProgressBar(std::string label, size_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled),
      tty_(isatty(fileno(stderr)) != 0),
      start_(std::chrono::steady_clock::now()),
      last_(start_)
{
}

void ProgressBar::update(size_t done, const std::string& extra)
{
	if (!enabled_) return;
	lastDone_ = done;
	const auto now = std::chrono::steady_clock::now();
	if (tty_)
	{
		if (now - last_ < std::chrono::milliseconds(200)) return;
	}
	else
	{
		const size_t pct = total_ ? (100 * done) / total_ : 0;
		if (total_ == 0 || pct / 10 == lastPct_ / 10) return;
		lastPct_ = pct;
	}
	last_ = now;
	draw(done, extra, false);
}

void ProgressBar::finish(const std::string& extra)
{
	if (!enabled_ || finished_) return;
	finished_ = true;
	draw(total_ ? total_ : lastDone_, extra, true);
}

void ProgressBar::draw(size_t done, const std::string& extra, bool final)
{
	const double secs =
	    std::chrono::duration<double>(std::chrono::steady_clock::now() - start_)
	        .count();
	const double rate = secs > 0 ? done / secs : 0.0;
	char bar[32] = {0};
	const int width = 24;
	const int filled =
	    total_ ? static_cast<int>((width * std::min(done, total_)) / total_)
	           : 0;
	for (int i = 0; i < width; i++) bar[i] = i < filled ? '#' : ' ';
	if (total_)
		std::fprintf(stderr, "%s%s [%s] %zu/%zu %.1f/s %.1fs %s%s",
		             tty_ ? "\r" : "", label_.c_str(), bar, done, total_, rate,
		             secs, extra.c_str(), (final || !tty_) ? "\n" : "\033[K");
	else
		std::fprintf(stderr, "%s%s %zu %.1f/s %.1fs %s%s", tty_ ? "\r" : "",
		             label_.c_str(), done, rate, secs, extra.c_str(),
		             (final || !tty_) ? "\n" : "\033[K");
	std::fflush(stderr);
}

}  // namespace bims
