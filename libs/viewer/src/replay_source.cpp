#include <bims/io/rawlog.h>
#include <bims/viewer/replay_source.h>

#include <stdexcept>

namespace bims::viewer
{
ReplaySource::ReplaySource(const std::string& path, source::FrameOrderParams p)
    : path_(path), p_(std::move(p))
{
	source::FrameOrderParams index = p_;
	index.depthCorrection.enable = false;  // the stamps are enough
	index.program = "bims-viewer";
	index.warnings = false;  // the replay warns, once per replay
	source::RawlogFrameSource all({path_}, index, false);
	while (auto f = all.next()) times_.push_back(f->t);
	if (!all.error().empty()) throw RawlogError(all.error());
	nImu_ = all.stats().imuRead;
	if (times_.empty())
		throw std::runtime_error(
		    path + ": no 3D range scan" +
		    (p_.sensors.rgbd_label.empty()
		         ? std::string()
		         : " with sensorLabel '" + p_.sensors.rgbd_label + "'") +
		    " (check [sensors] rgbd_label)");
	rewind();
}

void ReplaySource::rewind()
{
	src_.reset();
	src_ = std::make_unique<source::RawlogFrameSource>(
	    std::vector<std::string>{path_}, p_, false);
}

std::optional<source::SourceFrame> ReplaySource::next()
{
	return src_->next();
}

}  // namespace bims::viewer
