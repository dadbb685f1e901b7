#include "read_ahead.h"
#include <bims/common/errors.h>

#include <bims/common/clock.h>
#include <bims/common/cpu_time.h>

#include <pthread.h>

#include <algorithm>
#include <chrono>
#include <exception>

namespace bims::source
{
ReadAhead::ReadAhead(std::vector<std::string> paths, size_t capacity,
                     bool threaded)
    : paths_(std::move(paths)), capacity_(capacity < 1 ? 1 : capacity)
{
	for (const auto& p : paths_)
	{
		bytesBefore_.push_back(bytesTotal_);
		bytesTotal_ += rawlogDataBytes(p);
	}
	if (threaded) thread_ = std::thread([this] { loop(); });
}

ReadAhead::~ReadAhead()
{
	if (!thread_.joinable()) return;
	{
		std::lock_guard<std::mutex> lk(mu_);
		stop_ = true;
	}
	cv_.notify_all();
	thread_.join();
}

ReadAhead::Item ReadAhead::readOne(std::string& error)
{
	const auto t0 = std::chrono::steady_clock::now();
	const double cpu0 = threadCpuMs();
	Item it;
	if (!error_.empty())
	{
		error = error_;  // the stream stopped there
		return it;
	}
	try
	{
		while (!done_ && !it.obs)
		{
			if (!reader_)
			{
				if (file_ >= paths_.size())
				{
					done_ = true;
					break;
				}
				reader_ = std::make_unique<RawlogReader>(paths_[file_]);
			}
			it.obs = reader_->next();
			it.file = file_;
			it.entry = reader_->observationsRead() - 1;
			if (bytesTotal_ > 0)
				it.inputFraction = std::min(
				    1.0, double(bytesBefore_[file_] + reader_->bytesRead()) /
				             double(bytesTotal_));
			if (!it.obs)
			{
				reader_.reset();
				++file_;
			}
		}
		// external images: loaded here, while this file's images folder is
		// the current one
		if (it.obs)
		{
			try
			{
				it.obs->load();
			}
			catch (const std::exception& e)
			{
				throw RawlogError(
				    paths_[it.file] + ": observation " +
				    std::to_string(reader_->observationsRead()) +
				    ": cannot load its external data: " + e.what());
			}
		}
	}
	catch (const std::exception& e)
	{
		error = withoutBacktrace(e.what());
		if (error.empty()) error = "rawlog reading failed";
		error_ = error;
		it.obs.reset();
		done_ = true;
	}
	it.readCpuMs = threadCpuMs() - cpu0;
	it.readMs = msSince(t0);
	return it;
}

void ReadAhead::loop()
{
	pthread_setname_np(pthread_self(), "bims-read");  // for top, perf
	for (;;)
	{
		Entry e;
		e.item = readOne(e.error);
		const bool last = !e.item.obs;
		std::unique_lock<std::mutex> lk(mu_);
		cv_.wait(lk, [&] { return queue_.size() < capacity_ || stop_; });
		if (stop_) return;
		queue_.push_back(std::move(e));
		lk.unlock();
		cv_.notify_all();
		if (last) return;
	}
}

ReadAhead::Item ReadAhead::next(double* waitMs)
{
	const auto t0 = std::chrono::steady_clock::now();
	Entry e;
	if (!thread_.joinable())
		e.item = readOne(e.error);
	else
	{
		std::unique_lock<std::mutex> lk(mu_);
		cv_.wait(lk, [&] { return !queue_.empty(); });
		// the end marker and an error stay: the thread has stopped, and
		// further calls return them again
		if (queue_.front().item.obs)
		{
			e = std::move(queue_.front());
			queue_.pop_front();
		}
		else
			e = queue_.front();
		lk.unlock();
		cv_.notify_all();
	}
	if (waitMs) *waitMs = msSince(t0);
	if (!e.error.empty()) throw RawlogError(e.error);
	return e.item;
}

}  // namespace bims::source
