// Programs run as child processes, a few at a time (bims-sweep's runs).
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

namespace bims::sweep
{
/** One program to run: argv[0] is its path; stdout and stderr go to log. */
struct Job
{
	std::vector<std::string> argv;
	std::string log;
};

/** How a job ended. */
struct JobOutcome
{
	bool started = false;  ///< false: not launched (stopped before)
	/** Exit code; 128 + N when signal N ended it; -1 when not started. */
	int exitCode = -1;
	int signal = 0;      ///< the signal that ended it (0: it exited)
	double seconds = 0;  ///< wall time from launch to exit
};

struct PoolOptions
{
	size_t workers = 1;  ///< jobs running at once (>= 1)
	/** When it turns true (bims::installStopSignals), no job is launched
	 * any more and the running ones get stopSignal() (SIGINT if it returns
	 * 0) once; the pool then waits for them. */
	const std::atomic<bool>* stop = nullptr;
	std::function<int()> stopSignal;
	/** Called on the calling thread as each job ends (index, outcome). */
	std::function<void(size_t, const JobOutcome&)> onDone;
};

/** Runs \a jobs in order, at most workers at a time, each in a process
 * group of its own (a Ctrl-C on the terminal reaches only this process,
 * which forwards it once) that gets SIGTERM if this process dies. A job
 * that cannot be executed ends with exit code 127 and the reason in its
 * log. Throws (before launching that job) when a log cannot be created;
 * the jobs already running are waited for first. Returns one outcome per
 * job. Single-threaded: call it from the main thread. */
std::vector<JobOutcome> runJobs(const std::vector<Job>& jobs,
                                const PoolOptions& opt);

}  // namespace bims::sweep
