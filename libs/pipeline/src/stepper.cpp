#include <bims/common/cpu_time.h>
#include <bims/pipeline/stepper.h>

#include <stdexcept>

namespace bims::pipeline
{
FrameStepper::FrameStepper(Pipeline& pipe, bool live)
    : pipe_(pipe),
      lookahead_(!live && pipe.config().pipeline.flow_thread &&
                 pipe.config().pipeline.flow_lookahead)
{
}

void FrameStepper::add(source::SourceFrame f)
{
	for (const auto& m : f.imu) pipe_.addImu(*m);
	frames_.push_back(std::move(f));
}

std::optional<SteppedFrame> FrameStepper::run(bool end)
{
	if (frames_.empty() || (lookahead_ && !end && frames_.size() < 2))
		return std::nullopt;
	source::SourceFrame f = std::move(frames_.front());
	frames_.pop_front();
	Pipeline::Next next;
	if (lookahead_ && !frames_.empty())
	{
		next.scan = frames_.front().scan.get();
		next.index = frames_.front().index;
	}
	const double cpu0 = threadCpuMs();
	const FrameResult& r = pipe_.processFrame(*f.scan, f.index, next);
	cpuMs_ = threadCpuMs() - cpu0;
	return SteppedFrame{std::move(f), r};
}

LiveSegmentation::LiveSegmentation(const ExperimentConfig& cfg,
                                   const std::string& program,
                                   std::string device, bool keepInput)
    : pipe_(cfg),
      order_(
          [&]
          {
	          auto p = source::FrameOrderParams::of(
	              cfg.ego, cfg.pipeline.imu_wait_s, program);
	          p.keepInput = keepInput;
	          return p;
          }()),
      stepper_(pipe_, true),
      device_(std::move(device))
{
}

void LiveSegmentation::runReady(bool end, const OnFrame& onFrame)
{
	while (auto f = order_.pop()) stepper_.add(std::move(*f));
	while (auto done = stepper_.run(end))
		if (onFrame) onFrame(done->input, done->result);
}

void LiveSegmentation::push(const mrpt::obs::CObservation::Ptr& obs,
                            const OnFrame& onFrame)
{
	const bool more = order_.push(obs, {&device_, entry_++});
	runReady(!more, onFrame);
	if (!more && !order_.error().empty())
		throw std::runtime_error(order_.error());
}

void LiveSegmentation::finish(const OnFrame& onFrame)
{
	order_.finish({&device_, entry_});
	runReady(true, onFrame);
}

}  // namespace bims::pipeline
