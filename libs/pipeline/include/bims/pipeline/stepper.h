// Runs a Pipeline over the frames of a source (bims/source/frame_source.h)
// the same way for every program (bims-run, the viewer, bims-grab
// --live-segmentation), so that each sees the same results to the last bit:
// a frame's IMU samples are fed when the frame is added; with [pipeline]
// flow_thread and flow_lookahead a frame runs once the frame after it was
// added too, which the pipeline pairs with it (its observed flow starts on
// the flow thread during this frame's grids; one frame of latency).
#pragma once

#include <bims/pipeline/pipeline.h>
#include <bims/source/frame_source.h>

#include <deque>
#include <functional>
#include <optional>
#include <string>

namespace bims::pipeline
{
/** A frame FrameStepper::run() ran: the input and what it produced (the
 * pipeline's last(): valid until the next frame runs). */
struct SteppedFrame
{
	source::SourceFrame input;
	const FrameResult& result;
};

class FrameStepper
{
 public:
	/** \a live: frames come from a sensor as it records, so none waits
	 * for the next one (the look-ahead of [pipeline] flow_lookahead would
	 * add a sensor period to every frame's latency). */
	explicit FrameStepper(Pipeline& pipe, bool live = false);

	/** Takes the input's next frame: its IMU samples go to the pipeline. */
	void add(source::SourceFrame f);
	/** Runs the oldest frame added, if it may run now (looking ahead: once
	 * the frame after it is at hand, or at the \a end of the input).
	 * Returns it with its result, or nullopt. */
	std::optional<SteppedFrame> run(bool end = false);
	/** CPU time of the calling thread in the last run() that ran a frame
	 * [ms]. */
	double lastCpuMs() const { return cpuMs_; }
	Pipeline& pipeline() { return pipe_; }

 private:
	Pipeline& pipe_;
	bool lookahead_;
	std::deque<source::SourceFrame> frames_;
	double cpuMs_ = 0;
};

/** The pipeline over observations as they come from live sensors: the one
 * ordering rule (source::FrameOrder) and a live FrameStepper (no frame
 * waits for the next). */
class LiveSegmentation
{
 public:
	/** Called for every frame run, with its results. */
	using OnFrame =
	    std::function<void(const source::SourceFrame&, const FrameResult&)>;

	/** \a program names it in warnings; \a device in them too.
	 * \a keepInput: each frame carries the IMU observations before it
	 * (source::SourceFrame::before), for a writer of the input
	 * (RunRecorder). */
	LiveSegmentation(const ExperimentConfig& cfg, const std::string& program,
	                 std::string device, bool keepInput = false);
	/** Takes the next observation (IMU or 3D scan, in the order they came)
	 * and runs the frames it makes ready. */
	void push(const mrpt::obs::CObservation::Ptr& obs, const OnFrame& onFrame);
	/** The end of the input: runs every frame left. */
	void finish(const OnFrame& onFrame);
	const source::FrameOrderStats& stats() const { return order_.stats(); }
	/** The pipeline that runs the frames (its grids: the static map). */
	Pipeline& pipeline() { return pipe_; }
	/** The CPU time of the last frame run [ms] (FrameStepper::lastCpuMs). */
	double lastCpuMs() const { return stepper_.lastCpuMs(); }
	/** keepInput: the observations after the last frame, after finish(). */
	std::vector<mrpt::obs::CObservation::Ptr> takeTrailing()
	{
		return order_.takeTrailing();
	}

 private:
	void runReady(bool end, const OnFrame& onFrame);

	Pipeline pipe_;
	source::FrameOrder order_;
	FrameStepper stepper_;
	std::string device_;
	size_t entry_ = 0;
};

}  // namespace bims::pipeline
