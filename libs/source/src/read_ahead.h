// Internal: the observations of rawlog files, one file after the other, read
// and decoded ahead on a thread (RawlogFrameSource's input). Each observation
// is fully loaded (external images too) before it is handed over. Reading
// errors (bims::RawlogError naming the file and the entry) reach next() in
// stream order, after every observation read before them. Without a thread
// (threaded = false) next() reads on the caller's thread.
#pragma once

#include <bims/io/rawlog.h>

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace bims::source
{
class ReadAhead
{
 public:
	struct Item
	{
		mrpt::obs::CObservation::Ptr obs;  ///< nullptr: end of the last file
		size_t file = 0;                   ///< index into the paths
		size_t entry = 0;      ///< its observation index in that file
		double readMs = 0;     ///< time reading and decoding it took
		double readCpuMs = 0;  ///< its CPU time (the reading thread's)
		/** Share of all the files' data read with it (0..1; 0 when their
		 * size is unknown), for the progress line. */
		double inputFraction = 0;
	};

	ReadAhead(std::vector<std::string> paths, size_t capacity, bool threaded);
	/** Stops reading and joins. */
	~ReadAhead();
	ReadAhead(const ReadAhead&) = delete;
	ReadAhead& operator=(const ReadAhead&) = delete;

	/** The next observation (obs == nullptr at the end). Throws the reading
	 * error met at this point of the stream. \a waitMs: time blocked. */
	Item next(double* waitMs = nullptr);
	const std::string& path(size_t file) const { return paths_[file]; }

 private:
	/** Reads one item on the calling thread (error: message, obs null). */
	Item readOne(std::string& error);
	void loop();

	std::vector<std::string> paths_;
	/** rawlogDataBytes of the files before each file, and of all */
	std::vector<uint64_t> bytesBefore_;
	uint64_t bytesTotal_ = 0;
	size_t capacity_;
	// reading state (the reader thread's, or the caller's)
	size_t file_ = 0;
	std::unique_ptr<RawlogReader> reader_;
	bool done_ = false;
	std::string error_;  ///< the reading error, once met
	// queue
	struct Entry
	{
		Item item;
		std::string error;
	};
	std::mutex mu_;
	std::condition_variable cv_;
	std::deque<Entry> queue_;
	bool stop_ = false;
	std::thread thread_;
};

}  // namespace bims::source
