#include <bims/viewer/replay_source.h>

#include <mrpt/core/Clock.h>

#include <stdexcept>

namespace bims::viewer
{
namespace
{
bool labelMatches(const std::string& want, const std::string& have)
{
	return want.empty() || want == have;
}
}  // namespace

ReplaySource::ReplaySource(const std::string& path, const ReplaySourceParams& p)
    : path_(path), p_(p)
{
	RawlogReader r(path);
	while (auto o = r.next())
	{
		if (auto s =
		        std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
		            o))
		{
			if (labelMatches(p_.rgbdLabel, s->sensorLabel))
				times_.push_back(mrpt::Clock::toDouble(s->timestamp));
		}
		else if (std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o))
			++nImu_;
	}
	if (times_.empty())
		throw std::runtime_error(
		    path + ": no 3D range scan" +
		    (p_.rgbdLabel.empty()
		         ? std::string()
		         : " with sensorLabel '" + p_.rgbdLabel + "'") +
		    " (check [sensors] rgbd_label)");
	rewind();
}

void ReplaySource::rewind()
{
	reader_ = std::make_unique<RawlogReader>(path_);
	pending_.clear();
	imu_.clear();
	haveImu_ = haveAny_ = eof_ = false;
	lastImuT_ = newestT_ = 0;
	scanIndex_ = 0;
}

std::optional<ReplayFrame> ReplaySource::next()
{
	for (;;)
	{
		if (!pending_.empty())
		{
			ReplayFrame& f = pending_.front();
			const bool imuReady = haveImu_ && f.t + p_.imuOffsetS <= lastImuT_;
			const bool waited = newestT_ - f.t > p_.imuWaitS;
			if (imuReady || waited || eof_)
			{
				ReplayFrame out = std::move(f);
				pending_.pop_front();
				out.imu.swap(imu_);
				imu_.clear();
				return out;
			}
		}
		else if (eof_)
			return std::nullopt;

		auto o = reader_->next();
		if (!o)
		{
			eof_ = true;
			continue;
		}
		const double t = mrpt::Clock::toDouble(o->timestamp);
		if (!haveAny_ || t > newestT_) newestT_ = t;
		haveAny_ = true;
		if (auto s =
		        std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
		            o))
		{
			if (!labelMatches(p_.rgbdLabel, s->sensorLabel)) continue;
			ReplayFrame f;
			f.index = scanIndex_++;
			f.t = t;
			f.scan = s;
			pending_.push_back(std::move(f));
		}
		else if (auto m =
		             std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o))
		{
			if (!labelMatches(p_.imuLabel, m->sensorLabel)) continue;
			imu_.push_back(m);
			lastImuT_ = haveImu_ ? std::max(lastImuT_, t) : t;
			haveImu_ = true;
		}
	}
}

}  // namespace bims::viewer
