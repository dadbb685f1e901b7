// Internal: one background thread that runs jobs in the order they were
// posted (bims-run's output writing, the pipeline's flow thread). The queue is
// bounded: post() blocks while `capacity` jobs wait, so a slow disk slows the
// run down instead of filling the memory. The first job that throws stops the
// worker: later jobs are dropped, and post() and drain() throw its message.
// Without a thread (threaded = false) post() runs the job at once.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace bims::pipeline
{
class SerialWorker
{
 public:
	/** \a name: the thread's name (for top, perf; at most 15 characters). */
	SerialWorker(size_t capacity, bool threaded,
	             const char* name = "bims-write");
	/** Runs what is still queued, then joins (errors are dropped: call
	 * drain() first to see them). */
	~SerialWorker();
	SerialWorker(const SerialWorker&) = delete;
	SerialWorker& operator=(const SerialWorker&) = delete;

	/** Queues \a job; returns the time spent waiting for room [ms]. Throws
	 * std::runtime_error with the message of an earlier failed job. */
	double post(std::function<void()> job);
	/** Waits until every posted job has run; throws as post() does. */
	void drain();
	bool threaded() const { return thread_.joinable(); }

 private:
	void loop();
	void throwIfFailed();  // with mu_ held

	size_t capacity_;
	std::string name_;
	std::mutex mu_;
	std::condition_variable cv_;
	std::deque<std::function<void()>> jobs_;
	bool busy_ = false, stop_ = false;
	std::string error_;
	std::thread thread_;
};

}  // namespace bims::pipeline
