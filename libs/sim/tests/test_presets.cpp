// The scene presets of config/sim/: each loads, renders, and has the property
// its name promises.
#include <bims/sim/simulator.h>
#include <gtest/gtest.h>

#include <cmath>

using namespace bims::sim;

namespace
{
const std::string kPresets = std::string(BIMS_SOURCE_DIR) + "/config/sim/";

/** A preset's scene seen along its motion at 320x240 (built once). */
struct PresetView
{
	explicit PresetView(const SimConfig& c)
	    : scene(c.buildScene()), r(cam320(c), c.depth, c.rgb), motion(c.motion)
	{
	}
	static CameraParams cam320(const SimConfig& c)
	{
		CameraParams cam = c.camera;
		cam.setResolution("320x240");
		return cam;
	}
	RenderedFrame at(double t, uint64_t seed = 0) const
	{
		const auto k = motion.at(t);
		RenderedFrame f;
		r.render(scene, t, k.R_WC, k.p_WC, 1, seed, f);
		return f;
	}
	Scene scene;
	Renderer r;
	HandheldMotion motion;
};
/** Share of the frame's pixels that move, or that belong to object \a id. */
double share(const RenderedFrame& f, int id = -1)
{
	size_t m = 0;
	for (size_t i = 0; i < f.mask.size(); i++)
		m += (id < 0 ? f.mask[i] != 0 : f.objectId[i] == id) ? 1 : 0;
	return double(m) / f.mask.size();
}
/** Mean fraction of moving pixels over n frames spread over the sequence. */
double movingFraction(const SimConfig& c, int n)
{
	const PresetView view(c);
	double sum = 0;
	for (int i = 0; i < n; i++)
		sum += share(
		    view.at((c.seq.frames - 1) / c.seq.fps * i / std::max(1, n - 1),
		            uint64_t(i)));
	return sum / n;
}
double peakRateDegS(const SimConfig& c)
{
	const HandheldMotion m(c.motion);
	double peak = 0;
	for (double t = 0; t < c.seq.frames / c.seq.fps; t += 0.002)
		peak = std::max(peak, m.at(t).omega_C.norm());
	return peak * 180 / M_PI;
}
}  // namespace

TEST(Presets, AllLoadAndShowMovingObjects)
{
	for (const char* p : {"pendulum_slow", "fast_rotation", "static_camera",
	                      "crowded", "mag_disturbance"})
	{
		SCOPED_TRACE(p);
		const SimConfig c = SimConfig::load(kPresets + p + ".ini");
		EXPECT_GE(c.seq.frames, 150);
		EXPECT_GE(c.imu.rateHz, 100.0);
		EXPECT_GT(movingFraction(c, 4), 0.005);
	}
}

TEST(Presets, EachHasItsPromisedProperty)
{
	const auto slow = SimConfig::load(kPresets + "pendulum_slow.ini");
	EXPECT_LT(peakRateDegS(slow), 30.0);
	EXPECT_EQ(slow.pendulums.size(), 1u);
	EXPECT_GT(peakRateDegS(SimConfig::load(kPresets + "fast_rotation.ini")),
	          180.0);
	EXPECT_LT(peakRateDegS(SimConfig::load(kPresets + "static_camera.ini")),
	          1e-12);
	const double crowded =
	    movingFraction(SimConfig::load(kPresets + "crowded.ini"), 12);
	EXPECT_GT(crowded, 0.22);
	EXPECT_LT(crowded, 0.42);
	const auto mag = SimConfig::load(kPresets + "mag_disturbance.ini");
	ASSERT_TRUE(mag.imu.disturbance);
	// The camera passes through the disturbed region and out of it.
	const HandheldMotion m(mag.motion);
	double fmin = 1e9, fmax = 0;
	for (double t = 0; t < mag.seq.frames / mag.seq.fps; t += 0.05)
	{
		const Eigen::Vector3d d =
		    mag.imu.field_W(m.at(t).p_WC) - mag.imu.earthField_W();
		fmin = std::min(fmin, d.norm());
		fmax = std::max(fmax, d.norm());
	}
	EXPECT_LT(fmin, 0.02);
	EXPECT_GT(fmax, 0.15);
	const auto mis = SimConfig::load(kPresets + "imu_misaligned.ini");
	EXPECT_GT(
	    Eigen::AngleAxisd(mis.imu.R_IC.transpose() * slow.imu.R_IC).angle() *
	        180 / M_PI,
	    3.0);
	EXPECT_NE(mis.imu.timeOffsetS, 0.0);
	// occluder: the room (and a walker) first, the box (object 1) out of
	// view, then the box over half the image for at least 1 s
	const auto occ = SimConfig::load(kPresets + "occluder.ini");
	const PresetView occView(occ);
	double before = 0, longest = 0, run = 0;
	for (double t = 0; t < occ.seq.frames / occ.seq.fps; t += 0.1)
	{
		const RenderedFrame frame = occView.at(t);
		const double f = share(frame);
		if (t < 0.95) before = std::max(before, share(frame, 1));
		run = f >= 0.5 ? run + 0.1 : 0;
		longest = std::max(longest, run);
	}
	EXPECT_EQ(before, 0.0);
	EXPECT_GE(longest, 1.0);
}
