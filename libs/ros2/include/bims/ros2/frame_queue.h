// The queue between bims-ros2's receiving thread and its processing one
// (docs/ros2.md, "Never behind silently"): items in arrival order; an item
// is a frame when its `scan` is set (IMU samples otherwise). Frames beyond
// the queue's size drop the oldest frame waiting; other items are never
// dropped.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

namespace bims::ros2
{
/** \a Item: movable, with a member `scan` that converts to bool (true: a
 * frame). */
template <typename Item>
class DropOldestQueue
{
 public:
	/** At most \a maxFrames frames wait (>= 1). */
	explicit DropOldestQueue(size_t maxFrames) : max_(maxFrames) {}

	/** Appends \a it; returns the number of frames dropped for it (the
	 * oldest waiting). */
	size_t push(Item it)
	{
		std::lock_guard<std::mutex> lk(m_);
		size_t dropped = 0;
		if (it.scan)
			for (frames_++; frames_ > max_; frames_--, dropped++)
				eraseOldestFrame();
		q_.push_back(std::move(it));
		cv_.notify_one();
		return dropped;
	}
	/** The next item (waiting for one), or nullopt once closed and empty. */
	std::optional<Item> pop()
	{
		std::unique_lock<std::mutex> lk(m_);
		cv_.wait(lk, [&] { return !q_.empty() || closed_; });
		if (q_.empty()) return std::nullopt;
		Item it = std::move(q_.front());
		q_.pop_front();
		if (it.scan) frames_--;
		return it;
	}
	/** No more items: pop() returns those waiting, then nullopt. */
	void close()
	{
		std::lock_guard<std::mutex> lk(m_);
		closed_ = true;
		cv_.notify_all();
	}

 private:
	void eraseOldestFrame()
	{
		for (auto i = q_.begin(); i != q_.end(); ++i)
			if (i->scan)
			{
				q_.erase(i);
				return;
			}
	}

	std::mutex m_;
	std::condition_variable cv_;
	std::deque<Item> q_;
	size_t max_, frames_ = 0;
	bool closed_ = false;
};

}  // namespace bims::ros2
