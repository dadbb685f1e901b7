// The replay off the GUI thread: a ReplayController on a thread of its own
// runs the pipeline and builds FrameViews; the GUI thread sends commands
// (never waits for them) and draws the newest finished view.
#pragma once

#include <bims/viewer/controller.h>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace bims::viewer
{
/** How playback meets a pipeline or a drawing slower than the data. */
enum class PlayMode
{
	/** The pipeline keeps the data's pace as far as it can and never waits
	 * for drawing: every frame is processed (the masks stay exact), the
	 * frames finished while the GUI was still drawing an earlier one are
	 * not drawn (counted). */
	RealTime,
	/** Every frame is drawn: the pipeline waits until the GUI has drawn a
	 * frame before it runs the next (playback slows to the slower of the
	 * two, never faster than the data). */
	EveryFrame
};
/** "realtime", "every-frame". */
const char* toString(PlayMode m);
/** From toString()'s names; throws std::invalid_argument. */
PlayMode playModeFromString(const std::string& s);

/** What the replay thread is doing, for the status bar. */
struct WorkerState
{
	bool playing = false;
	PlayMode mode = PlayMode::RealTime;
	double speed = 1;
	/** Frames the pipeline ran since the last restart. */
	size_t processed = 0;
	/** Of those, frames never drawn (real time: the GUI was behind). */
	size_t notDrawn = 0;
	/** "" or what takes a while, e.g. "seeking to frame 120 (57)". */
	std::string busy;
};

class ReplayWorker
{
 public:
	/** Opens the replay on the caller's thread (bad input throws here, as
	 * ReplayController does), then starts the replay thread. \a layers: the
	 * layers the views are built with. */
	ReplayWorker(const ViewerOptions& opt, const LayerVisibility& layers);
	/** Stops the replay thread (at once, also within a long seek). */
	~ReplayWorker();
	ReplayWorker(const ReplayWorker&) = delete;
	ReplayWorker& operator=(const ReplayWorker&) = delete;

	size_t frameCount() const { return frameCount_; }
	/** Whether the pipeline runs (false: replay or results folder only). */
	bool pipelineRunning() const { return pipelineRunning_; }

	// --- commands: queued, run in order on the replay thread; each returns
	// at once. Step, seek and restart pause playback.
	void play(bool on);
	void togglePlay();
	void step();
	/** Shows frame \a i (going back restarts the pipeline and runs it up to
	 * \a i; a later seek, step, restart or play interrupts it). */
	void seek(size_t i);
	void restart();
	void setSpeed(double s);
	void setMode(PlayMode m);
	/** Rebuilds the current frame's view with these layers. */
	void setLayers(const LayerVisibility& layers);

	// --- results
	/** The newest finished view (null before the first). Never waits for
	 * the pipeline. */
	std::shared_ptr<const FrameView> latest() const;
	/** The GUI has drawn view \a seq (EveryFrame waits for this; RealTime
	 * builds a view only once the previous one is drawn). */
	void drawn(uint64_t seq);
	WorkerState state() const;
	/** The error that stopped the replay thread's last command ("" none);
	 * cleared by the call. */
	[[nodiscard]] std::string takeError();
	/** Calls \a f on the replay thread with the controller and waits for it
	 * (tests, or reading the pipeline's state between frames). */
	void withController(const std::function<void(ReplayController&)>& f);
	/** Waits until no command is queued or running and playback has
	 * stopped (end reached or paused), at most \a seconds; true if so. */
	[[nodiscard]] bool waitIdle(double seconds) const;

 private:
	using Command = std::function<void()>;
	void post(Command c, bool interrupts = false);
	void loop();
	/** Runs \a f with \a lk unlocked; an exception stops playback and is
	 * kept for the GUI. Then mirrors the controller's state for the other
	 * threads. */
	void runUnlocked(std::unique_lock<std::mutex>& lk,
	                 const std::function<void()>& f);
	void publish();
	bool interrupted() const;  // a command that interrupts a seek is queued
	void doSeek(size_t i);

	std::unique_ptr<ReplayController> ctl_;
	const size_t frameCount_;
	const bool pipelineRunning_;

	mutable std::mutex m_;
	mutable std::condition_variable cv_;
	std::deque<std::pair<Command, bool>> queue_;
	bool running_ = false;  // a command is being run
	bool quit_ = false;
	PlayMode mode_ = PlayMode::RealTime;
	std::shared_ptr<const FrameView> latest_;
	uint64_t published_ = 0, drawn_ = 0;
	long ctlFrame_ = -1;       // the controller's frame, mirrored
	long viewFrame_ = -2;      // frame of latest_ (-2: none)
	bool layersDirty_ = true;  // latest_ was built with other layers
	WorkerState state_;
	std::string error_;
	std::thread thread_;
};

}  // namespace bims::viewer
