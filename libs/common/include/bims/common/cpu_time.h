// CPU time of the calling thread and of the process [ms], the
// cross-check of wall-clock stage times on a loaded machine; the process's
// peak resident memory.
#pragma once

#include <sys/resource.h>

#include <ctime>

namespace bims
{
inline double cpuMs(clockid_t clock)
{
	timespec ts{};
	clock_gettime(clock, &ts);
	return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * ts.tv_nsec;
}
inline double threadCpuMs()
{
	return cpuMs(CLOCK_THREAD_CPUTIME_ID);
}
inline double processCpuMs()
{
	return cpuMs(CLOCK_PROCESS_CPUTIME_ID);
}
/** Peak resident set size of the process so far [MiB] (Linux: ru_maxrss
 * is in KiB). */
inline double peakResidentMiB()
{
	rusage u{};
	getrusage(RUSAGE_SELF, &u);
	return static_cast<double>(u.ru_maxrss) / 1024.0;
}

}  // namespace bims
