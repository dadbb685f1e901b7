#include "worker.h"
#include <bims/common/clock.h>

#include <pthread.h>

#include <chrono>
#include <exception>
#include <stdexcept>

namespace bims::pipeline
{
SerialWorker::SerialWorker(size_t capacity, bool threaded, const char* name)
    : capacity_(capacity < 1 ? 1 : capacity), name_(name)
{
	if (threaded) thread_ = std::thread([this] { loop(); });
}

SerialWorker::~SerialWorker()
{
	if (!thread_.joinable()) return;
	{
		std::lock_guard<std::mutex> lk(mu_);
		stop_ = true;
	}
	cv_.notify_all();
	thread_.join();
}

void SerialWorker::throwIfFailed()
{
	if (!error_.empty()) throw std::runtime_error(error_);
}

double SerialWorker::post(std::function<void()> job)
{
	if (!thread_.joinable())
	{
		throwIfFailed();
		try
		{
			job();
		}
		catch (const std::exception& e)
		{
			error_ = e.what();
			throw;
		}
		return 0;
	}
	const auto t0 = std::chrono::steady_clock::now();
	std::unique_lock<std::mutex> lk(mu_);
	cv_.wait(lk, [&] { return jobs_.size() < capacity_ || !error_.empty(); });
	throwIfFailed();
	jobs_.push_back(std::move(job));
	lk.unlock();
	cv_.notify_all();
	return msSince(t0);
}

void SerialWorker::drain()
{
	std::unique_lock<std::mutex> lk(mu_);
	cv_.wait(lk, [&] { return (jobs_.empty() && !busy_) || !error_.empty(); });
	throwIfFailed();
}

void SerialWorker::loop()
{
	pthread_setname_np(pthread_self(), name_.substr(0, 15).c_str());
	std::unique_lock<std::mutex> lk(mu_);
	for (;;)
	{
		cv_.wait(lk, [&] { return !jobs_.empty() || stop_; });
		if (jobs_.empty()) return;  // stop_ and nothing left
		auto job = std::move(jobs_.front());
		jobs_.pop_front();
		busy_ = true;
		lk.unlock();
		cv_.notify_all();  // room in the queue
		std::string err;
		try
		{
			job();
		}
		catch (const std::exception& e)
		{
			err = e.what();
			if (err.empty()) err = "output writing failed";
		}
		catch (...)
		{
			err = "output writing failed (unknown exception)";
		}
		lk.lock();
		busy_ = false;
		if (!err.empty() && error_.empty())
		{
			error_ = err;
			jobs_.clear();
		}
		cv_.notify_all();
	}
}

}  // namespace bims::pipeline
