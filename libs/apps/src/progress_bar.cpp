#include <bims/apps/progress_bar.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace bims
{
std::string formatDuration(double s)
{
	char b[48];
	const long t = static_cast<long>(s + 0.5);
	if (t < 60)
		std::snprintf(b, sizeof(b), "%.1f s", s);
	else if (t < 3600)
		std::snprintf(b, sizeof(b), "%ld min %02ld s", t / 60, t % 60);
	else
		std::snprintf(b, sizeof(b), "%ld h %02ld min", t / 3600,
		              (t % 3600) / 60);
	return b;
}

ProgressBar::ProgressBar(std::string label, size_t total, bool enabled,
                         std::string unit)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      enabled_(enabled),
      tty_(isatty(fileno(stderr)) != 0),
      start_(std::chrono::steady_clock::now()),
      last_(start_)
{
}

void ProgressBar::setTotal(size_t total, bool estimated)
{
	total_ = total;
	estimated_ = estimated;
}

void ProgressBar::update(size_t done, const std::string& extra)
{
	if (!enabled_) return;
	lastDone_ = done;
	const auto now = std::chrono::steady_clock::now();
	const double since = std::chrono::duration<double>(now - last_).count();
	if (tty_)
	{
		if (since < 0.2) return;
	}
	else
	{
		if (total_ && done >= total_) return;  // finish() says it
		// a line at every tenth of the total, and at least every few
		// seconds
		const size_t tenth =
		    total_ ? (10 * std::min(done, total_)) / total_ : 0;
		if (tenth == lastTenth_ && since < kLineEverySeconds) return;
		lastTenth_ = tenth;
	}
	last_ = now;
	draw(done, extra, false);
}

void ProgressBar::finish(const std::string& extra)
{
	if (!enabled_ || finished_) return;
	finished_ = true;
	if (estimated_) total_ = lastDone_;  // the input is read: exact now
	estimated_ = false;
	draw(total_ ? std::max(total_, lastDone_) : lastDone_, extra, true);
}

ProgressCallback ProgressBar::callback()
{
	if (!enabled_) return {};
	return [this](const Progress& p) { report(p); };
}

void ProgressBar::report(const Progress& p)
{
	if (!reported_)
	{
		reported_ = true;
		start_ = last_ = std::chrono::steady_clock::now();
	}
	setTotal(p.total, p.estimated);
	if (p.finished)
		finish(p.note);
	else
		update(p.done, p.note);
}

std::string ProgressBar::text(size_t done, double secs, bool tty,
                              const std::string& extra) const
{
	const double rate = secs > 0 ? done / secs : 0.0;
	const std::string total =
	    total_
	        ? "/" + std::string(estimated_ ? "~" : "") + std::to_string(total_)
	        : "";
	const int pct =
	    total_ ? static_cast<int>((100 * std::min(done, total_)) / total_) : 0;
	const bool eta = total_ && rate > 0 && done < total_;
	const std::string etaText =
	    eta ? formatDuration((total_ - done) / rate) : "";
	char buf[256];
	if (tty)
	{
		std::string bar;
		const size_t width = 24;
		const size_t filled =
		    total_ ? (width * std::min(done, total_)) / total_ : 0;
		for (size_t i = 0; i < width; i++) bar += i < filled ? '#' : ' ';
		std::snprintf(buf, sizeof(buf), "%s [%s] %zu%s %s", label_.c_str(),
		              total_ ? bar.c_str() : "", done, total.c_str(),
		              unit_.c_str());
		std::string s = buf;
		if (total_) s += " " + std::to_string(pct) + " %";
		std::snprintf(buf, sizeof(buf), " %.1f/s", rate);
		s += buf;
		s += eta ? " ETA " + etaText : " " + formatDuration(secs);
		return s + (extra.empty() ? "" : " " + extra);
	}
	std::snprintf(buf, sizeof(buf), "%s: %zu%s %s", label_.c_str(), done,
	              total.c_str(), unit_.c_str());
	std::string s = buf;
	if (total_) s += " (" + std::to_string(pct) + " %)";
	std::snprintf(buf, sizeof(buf), ", %.1f %s/s, %s", rate, unit_.c_str(),
	              formatDuration(secs).c_str());
	s += buf;
	if (eta) s += ", ETA " + etaText;
	return s + (extra.empty() ? "" : ", " + extra);
}

void ProgressBar::draw(size_t done, const std::string& extra, bool final)
{
	const double secs =
	    std::chrono::duration<double>(std::chrono::steady_clock::now() - start_)
	        .count();
	const std::string line = text(done, secs, tty_, extra);
	if (tty_)
		std::fprintf(stderr, "\r%s\033[K%s", line.c_str(), final ? "\n" : "");
	else
		std::fprintf(stderr, "%s\n", line.c_str());
	std::fflush(stderr);
}

}  // namespace bims
