// Internal: CPU time of the calling thread and of the process [ms], the
// cross-check of wall-clock stage times on a loaded machine.
#pragma once

#include <ctime>

namespace bims::pipeline
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

}  // namespace bims::pipeline
