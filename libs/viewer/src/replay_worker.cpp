#include <bims/viewer/replay_worker.h>

#include <algorithm>
#include <chrono>
#include <future>
#include <stdexcept>

namespace bims::viewer
{
namespace
{
using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t)
{
	return std::chrono::duration<double>(Clock::now() - t).count();
}
}  // namespace

const char* toString(PlayMode m)
{
	return m == PlayMode::RealTime ? "realtime" : "every-frame";
}

PlayMode playModeFromString(const std::string& s)
{
	if (s == "realtime") return PlayMode::RealTime;
	if (s == "every-frame") return PlayMode::EveryFrame;
	throw std::invalid_argument("unknown play mode '" + s +
	                            "' (known: realtime, every-frame)");
}

ReplayWorker::ReplayWorker(const ViewerOptions& opt,
                           const LayerVisibility& layers)
    : ctl_(std::make_unique<ReplayController>(opt)),
      frameCount_(ctl_->frameCount()),
      pipelineRunning_(ctl_->pipelineRunning())
{
	ctl_->layers() = layers;
	state_.speed = ctl_->speed();
	thread_ = std::thread([this] { loop(); });
}

ReplayWorker::~ReplayWorker()
{
	{
		std::lock_guard<std::mutex> g(m_);
		quit_ = true;
	}
	cv_.notify_all();
	thread_.join();
}

void ReplayWorker::post(Command c, bool interrupts)
{
	{
		std::lock_guard<std::mutex> g(m_);
		queue_.emplace_back(std::move(c), interrupts);
	}
	cv_.notify_all();
}

void ReplayWorker::play(bool on)
{
	post([this, on] { ctl_->setPlaying(on); }, true);
}

void ReplayWorker::togglePlay()
{
	post([this] { ctl_->setPlaying(!ctl_->playing()); }, true);
}

void ReplayWorker::step()
{
	post(
	    [this]
	    {
		    ctl_->setPlaying(false);
		    ctl_->step();
	    },
	    true);
}

void ReplayWorker::seek(size_t i)
{
	post([this, i] { doSeek(i); }, true);
}

void ReplayWorker::restart()
{
	post([this] { doSeek(0); }, true);
}

void ReplayWorker::setSpeed(double s)
{
	post([this, s] { ctl_->setSpeed(s); });
}

void ReplayWorker::setMode(PlayMode m)
{
	{
		std::lock_guard<std::mutex> g(m_);
		mode_ = m;
		state_.mode = m;
	}
	cv_.notify_all();
}

void ReplayWorker::setLayers(const LayerVisibility& layers)
{
	post(
	    [this, layers]
	    {
		    ctl_->layers() = layers;
		    std::lock_guard<std::mutex> g(m_);
		    layersDirty_ = true;
	    });
}

std::shared_ptr<const FrameView> ReplayWorker::latest() const
{
	std::lock_guard<std::mutex> g(m_);
	return latest_;
}

void ReplayWorker::drawn(uint64_t seq)
{
	{
		std::lock_guard<std::mutex> g(m_);
		drawn_ = std::max(drawn_, seq);
	}
	cv_.notify_all();
}

WorkerState ReplayWorker::state() const
{
	std::lock_guard<std::mutex> g(m_);
	return state_;
}

std::string ReplayWorker::takeError()
{
	std::lock_guard<std::mutex> g(m_);
	std::string e;
	e.swap(error_);
	return e;
}

void ReplayWorker::withController(
    const std::function<void(ReplayController&)>& f)
{
	std::promise<void> done;
	post(
	    [&]
	    {
		    try
		    {
			    f(*ctl_);
			    done.set_value();
		    }
		    catch (...)
		    {
			    done.set_exception(std::current_exception());
		    }
	    });
	done.get_future().get();
}

bool ReplayWorker::waitIdle(double seconds) const
{
	std::unique_lock<std::mutex> lk(m_);
	return cv_.wait_for(
	    lk, std::chrono::duration<double>(seconds),
	    [this]
	    {
		    const bool viewDue = (viewFrame_ != ctlFrame_ || layersDirty_) &&
		                         drawn_ >= published_;
		    return queue_.empty() && !running_ && !state_.playing && !viewDue;
	    });
}

bool ReplayWorker::interrupted() const
{
	std::lock_guard<std::mutex> g(m_);
	if (quit_) return true;
	return std::any_of(queue_.begin(), queue_.end(),
	                   [](const auto& c) { return c.second; });
}

void ReplayWorker::doSeek(size_t i)
{
	ctl_->setPlaying(false);
	if (frameCount_ == 0) return;
	i = std::min(i, frameCount_ - 1);
	const long target = static_cast<long>(i);
	if (target < ctl_->currentFrame() || ctl_->currentFrame() < 0)
	{
		ctl_->seek(0);  // restarts: the pipeline is causal
		std::lock_guard<std::mutex> g(m_);
		state_.notDrawn = 0;
	}
	while (ctl_->currentFrame() < target && !interrupted())
	{
		{
			std::lock_guard<std::mutex> g(m_);
			state_.busy = "seeking to frame " + std::to_string(target) +
			              " (at " + std::to_string(ctl_->currentFrame()) + ")";
			state_.processed = static_cast<size_t>(ctl_->currentFrame() + 1);
			ctlFrame_ = ctl_->currentFrame();
		}
		cv_.notify_all();
		if (!ctl_->step()) break;
	}
	std::lock_guard<std::mutex> g(m_);
	state_.busy.clear();
}

void ReplayWorker::publish()
{
	auto v = ctl_->view();
	std::lock_guard<std::mutex> g(m_);
	v->seq = ++published_;
	viewFrame_ = v->frame;
	layersDirty_ = false;
	latest_ = std::move(v);
}

void ReplayWorker::runUnlocked(std::unique_lock<std::mutex>& lk,
                               const std::function<void()>& f)
{
	lk.unlock();
	std::string err;
	try
	{
		f();
	}
	catch (const std::exception& e)
	{
		err = e.what();
		ctl_->setPlaying(false);
	}
	lk.lock();
	if (!err.empty()) error_ = err;
	ctlFrame_ = ctl_->currentFrame();
	state_.playing = ctl_->playing();
	state_.speed = ctl_->speed();
	state_.processed = static_cast<size_t>(ctlFrame_ + 1);
	cv_.notify_all();
}

void ReplayWorker::loop()
{
	auto lastTick = Clock::now();
	std::unique_lock<std::mutex> lk(m_);
	const auto unlocked = [&](const std::function<void()>& f)
	{ runUnlocked(lk, f); };
	while (!quit_)
	{
		if (!queue_.empty())
		{
			Command c = std::move(queue_.front().first);
			queue_.pop_front();
			running_ = true;
			const long before = ctlFrame_;
			unlocked(c);
			running_ = false;
			if (ctlFrame_ < before) state_.notDrawn = 0;  // restarted
			lastTick = Clock::now();
			cv_.notify_all();
			continue;
		}
		const bool guiFree = drawn_ >= published_;
		const bool stale = viewFrame_ != ctlFrame_ || layersDirty_;
		if (stale && guiFree)
		{
			unlocked([&] { publish(); });
			continue;
		}
		if (!state_.playing)
		{
			cv_.wait(lk);
			continue;
		}
		// Playing. EveryFrame: the next frame only once this one is drawn.
		if (mode_ == PlayMode::EveryFrame && (stale || !guiFree))
		{
			cv_.wait(lk);
			continue;
		}
		lk.unlock();
		const double wait = ctl_->secondsToNextFrame() - secondsSince(lastTick);
		lk.lock();
		if (wait > 0)
		{
			cv_.wait_for(lk,
			             std::chrono::duration<double>(std::min(wait, 0.05)));
			continue;
		}
		const bool skipped = stale && ctlFrame_ >= 0;
		size_t n = 0;
		unlocked(
		    [&]
		    {
			    const double dt = secondsSince(lastTick);
			    lastTick = Clock::now();
			    n = ctl_->advance(dt, 1);
		    });
		if (n > 0 && skipped) ++state_.notDrawn;
	}
}

}  // namespace bims::viewer
