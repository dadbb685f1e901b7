// driver=SimImu: the simulator's IMU (libs/sim) sampled in real time on the
// host clock, for grabbing without an IMU.
#include <bims/common/config.h>
#include <bims/grab/host_clock.h>
#include <bims/grab/imu_source.h>
#include <bims/sim/imu.h>
#include <bims/sim/motion.h>

#include <cmath>

namespace bims::grab
{
namespace
{
class SimImuSource : public ImuSource
{
 public:
	SimImuSource(const sim::ImuParams& p, bool moving, uint64_t seed)
	    : p_(p), sim_(p, seed), moving_(moving)
	{
		sim::HandheldMotionParams m;
		if (!moving) m.posAmplitude.setZero(), m.rotAmplitudeDeg.setZero();
		motion_ = std::make_unique<sim::HandheldMotion>(m);
		start_ = hostNow();
	}
	std::vector<mrpt::obs::CObservationIMU::Ptr> poll() override
	{
		std::vector<mrpt::obs::CObservationIMU::Ptr> out;
		const double now = hostNow();
		for (;;)
		{
			const double t = start_ + n_ / p_.rateHz;
			if (t > now) break;
			out.push_back(sim_.sample(*motion_, t, start_));
			++n_;
		}
		return out;
	}
	std::string describe() const override
	{
		return "simulated IMU (libs/sim) at " + std::to_string(p_.rateHz) +
		       " Hz, camera " + (moving_ ? "hand-held" : "at rest") +
		       ", label " + p_.label;
	}

 private:
	sim::ImuParams p_;
	sim::ImuSimulator sim_;
	bool moving_;
	std::unique_ptr<sim::MotionModel> motion_;
	double start_ = 0;
	uint64_t n_ = 0;
};
}  // namespace

std::unique_ptr<ImuSource> makeSimImuSource(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	ConfigSection sec(cfg, section, true);
	sec.allow("driver");
	sim::ImuParams p;
	p.label = sec.getString("sensorLabel", "IMU");
	p.rateHz = sec.getDouble("rate_hz", p.rateHz, 1, 10000);
	const bool moving = sec.getBool("moving", false);
	const auto seed = static_cast<uint64_t>(sec.getInt("seed", 1, 0, 1L << 40));
	sec.finish();
	return std::make_unique<SimImuSource>(p, moving, seed);
}

}  // namespace bims::grab
