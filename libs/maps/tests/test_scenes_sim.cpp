// Behaviour on scenes rendered by the project's simulator (libs/sim: its
// furnished room, a sliding box, its depth model with projector shadows and
// grazing-angle limits, noiseless): static scene -> almost nothing flagged; a
// box moving into free space is flagged; with decay = raycast a static
// object that leaves the field of view is not forgotten (with decay = all
// it is). The test links bims::sim; the maps library does not.
#include <bims/common/frames.h>
#include <bims/maps/motion_grids.h>
#include <bims/sim/objects.h>
#include <bims/sim/renderer.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <gtest/gtest.h>

#include "test_util.h"

using namespace bims::maps;
namespace sim = bims::sim;

namespace
{
/** Renders frames of a simulator scene as CObservation3DRangeScan. */
class SimCamera
{
 public:
	SimCamera() : renderer_(cam(), depth(), sim::RgbParams()) {}
	/** The simulator's depth model without noise, dropout and holes (range,
	 * grazing-angle limits and projector shadows kept): with the default
	 * noise, decay = raycast frees surface voxels that noisy rays of other
	 * pixels pass through, and tier 1 then flags several % of a static
	 * scene (docs/journal/voxel-grids.md, "Voxel grids"); that is the model's
	 * behaviour, not what these tests are about. */
	static sim::DepthParams depth()
	{
		sim::DepthParams d;
		d.makeNoiseless();
		return d;
	}

	static sim::CameraParams cam()
	{
		sim::CameraParams c;
		c.setResolution("320x240");
		return c;
	}

	/** Frame \a k of \a scene at time \a t [s] seen from the scan frame
	 * {S} at T_WS; the ground truth (mask) in last(). */
	mrpt::obs::CObservation3DRangeScan::Ptr render(
	    const sim::Scene& scene, double t, const mrpt::poses::CPose3D& T_WS,
	    int k)
	{
		const mrpt::poses::CPose3D T_WC = T_WS + bims::T_SC();
		const Eigen::Matrix3d R_WC = T_WC.getRotationMatrix().asEigen();
		const Eigen::Vector3d p_WC(T_WC.x(), T_WC.y(), T_WC.z());
		renderer_.render(scene, t, R_WC, p_WC, 1, uint64_t(k), last_);
		const auto c = cam();
		auto o = mrpt::obs::CObservation3DRangeScan::Create();
		o->timestamp = mrpt::Clock::fromDouble(1000.0 + k / 30.0);
		o->hasRangeImage = true;
		o->range_is_depth = true;
		o->rangeUnits = 0.001f;
		o->rangeImage_setSize(last_.height, last_.width);
		for (int v = 0; v < last_.height; ++v)
			for (int u = 0; u < last_.width; ++u)
				o->rangeImage(v, u) =
				    last_.depthMm[size_t(v) * last_.width + u];
		o->cameraParams.ncols = last_.width;
		o->cameraParams.nrows = last_.height;
		o->cameraParams.setIntrinsicParamsFromValues(c.fxS(), c.fyS(), c.cxS(),
		                                             c.cyS());
		o->cameraParamsIntensity = o->cameraParams;
		o->maxRange = 10;
		return o;
	}
	const sim::RenderedFrame& last() const { return last_; }

 private:
	sim::Renderer renderer_;
	sim::RenderedFrame last_;
};

sim::Scene furnishedRoom()
{
	sim::Scene s;
	sim::buildRoom(sim::RoomParams(), s);
	return s;
}

constexpr DecayMode kModes[] = {DecayMode::All, DecayMode::Frustum,
                                DecayMode::Raycast};
}  // namespace

TEST(SimScenes, StaticSceneTier1FlagsUnderOnePercentAfterNFrames)
{
	const sim::Scene scene = furnishedRoom();
	// The simulator's default hand-held base pose, looking into the room.
	const mrpt::poses::CPose3D T(-1.5, 0, 1.3, 0, 5 * M_PI / 180, 0);
	for (auto mode : kModes)
	{
		GridParams p = test::paperGrids();
		p.decay = mode;
		MotionGrids mg(p);
		SimCamera cam;
		const int N = 5;
		size_t hit = 0, flagged = 0;
		for (int f = 0; f < N + 10; ++f)
		{
			const auto& r =
			    mg.processFrame(*cam.render(scene, f / 30.0, T, f), T, nullptr);
			if (f >= N)
			{
				hit += r.hitVoxels;
				flagged += r.movingTier1;
			}
		}
		ASSERT_GT(hit, 10000u);
		EXPECT_LT(double(flagged) / hit, 0.01) << bims::choiceName(mode);
	}
}

TEST(SimScenes, BoxMovingIntoFreeSpaceIsFlagged)
{
	// The simulator's sliding box, sampled at instants where it has moved
	// by more than its own width between frames (0.5 m at 30 Hz would be
	// too fast for a sequence; the instants, not the speed, matter here):
	// each frame it occupies cells that were free.
	sim::SlidingBoxParams bp;
	bp.center = {0.3, 0.0};
	bp.size = {0.3, 0.35, 1.0};
	bp.azimuthDeg = 90;  // along +y, across the view
	bp.amplitude = 1.0;
	bp.periodS = 4;
	const sim::Scene empty = furnishedRoom();
	sim::Scene withBox = furnishedRoom();
	withBox.objects.push_back(sim::makeSlidingBox("box", bp));
	// y = amplitude sin(2 pi t / period): t for y = -0.9, -0.4, 0.1, 0.6.
	std::vector<double> times;
	for (double y : {-0.9, -0.4, 0.1, 0.6})
		times.push_back(std::asin(y / bp.amplitude) * bp.periodS / (2 * M_PI));
	const mrpt::poses::CPose3D T(-2, 0, 1.2, 0, 0, 0);
	for (auto mode : kModes)
	{
		GridParams p = test::paperGrids();
		p.decay = mode;
		MotionGrids mg(p);
		SimCamera cam;
		int f = 0;
		for (; f < 6; ++f)
			mg.processFrame(*cam.render(empty, 0, T, f), T, nullptr);
		for (double t : times)
		{
			const auto scan = cam.render(withBox, t, T, f++);
			const auto& gt = cam.last();
			const auto& r = mg.processFrame(*scan, T, nullptr);
			size_t boxPx = 0, boxFlagged = 0, restPx = 0, restFlagged = 0;
			for (size_t i = 0; i < gt.mask.size(); ++i)
			{
				if (gt.depthMm[i] == 0) continue;
				const bool isBox = gt.mask[i] == 255;
				const bool fl = r.maskTier1().data[i] == 255;
				(isBox ? boxPx : restPx)++;
				(isBox ? boxFlagged : restFlagged) += fl;
			}
			ASSERT_GT(boxPx, 200u) << "t " << t;
			EXPECT_GT(double(boxFlagged) / boxPx, 0.9)
			    << bims::choiceName(mode) << " t " << t;
			EXPECT_LT(double(restFlagged) / restPx, 0.01)
			    << bims::choiceName(mode) << " t " << t;
		}
	}
}

TEST(SimScenes, RaycastRemembersAStaticObjectThatLeftTheView)
{
	// A static cabinet in front of the camera; then the camera turns round.
	sim::Scene scene = furnishedRoom();
	sim::Primitive cabinet;
	cabinet.shape = sim::Shape::Box;
	cabinet.t_WP = {1.0, 0.0, 0.75};
	cabinet.half = {0.2, 0.4, 0.75};
	cabinet.texture = 7;
	scene.staticPrims.push_back(cabinet);
	const mrpt::math::TPoint3D onFace(0.81, 0.05, 0.9);  // its front face
	double pAfter[3] = {0, 0, 0};
	int i = 0;
	for (auto mode : kModes)
	{
		GridParams p = test::paperGrids();
		p.decay = mode;
		MotionGrids mg(p);
		SimCamera cam;
		const mrpt::poses::CPose3D look(-1, 0, 1.0, 0, 0, 0);
		for (int f = 0; f < 5; ++f)
			mg.processFrame(*cam.render(scene, 0, look, f), look, nullptr);
		EXPECT_GT(mg.occupancy()->probabilityAt(onFace), 0.9)
		    << bims::choiceName(mode);
		const mrpt::poses::CPose3D away(-1, 0, 1.0, M_PI, 0, 0);
		for (int f = 5; f < 25; ++f)
			mg.processFrame(*cam.render(scene, 0, away, f), away, nullptr);
		pAfter[i++] = mg.occupancy()->probabilityAt(onFace);
	}
	EXPECT_NEAR(pAfter[0], 0.12, 1e-3);  // all: forgotten (p_min)
	EXPECT_GT(pAfter[1], 0.9);           // frustum: remembered
	EXPECT_GT(pAfter[2], 0.9);           // raycast: remembered
}
