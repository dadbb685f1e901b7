// Renderer: geometry of the depth, the noise model, the masks, the texture.
#include <bims/sim/objects.h>
#include <bims/sim/renderer.h>
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

using namespace bims::sim;

namespace
{
Scene pendulumScene()
{
	Scene s;
	buildRoom(RoomParams(), s);
	PendulumParams pp;
	pp.ballRadius = 0.25;
	s.objects.push_back(makePendulum("pendulum", pp));
	SlidingBoxParams bp;
	s.objects.push_back(makeSlidingBox("box", bp));
	return s;
}
Kinematics camAt(double t)
{
	return HandheldMotion(HandheldMotionParams()).at(t);
}
Eigen::Vector3d backProject(const CameraParams& c, int u, int v, double z,
                            const Kinematics& k)
{
	const Eigen::Vector3d p_C((u - c.cxS()) / c.fxS() * z,
	                          (v - c.cyS()) / c.fyS() * z, z);
	return k.R_WC * p_C + k.p_WC;
}
}  // namespace

TEST(Renderer, NoiselessDepthLiesOnTheSurfacesAndMaskMarksMovingOnes)
{
	const Scene scene = pendulumScene();
	CameraParams cam;
	DepthParams dp;
	dp.makeNoiseless();
	const Renderer r(cam, dp, RgbParams());
	for (double t : {0.0, 0.7, 2.3})
	{
		const auto k = camAt(t);
		RenderedFrame f;
		r.render(scene, t, k.R_WC, k.p_WC, 1, 0, f);
		const auto prims = scene.primitivesAt(t);
		size_t valid = 0, moving = 0;
		for (int v = 0; v < f.height; v += 3)
			for (int u = 0; u < f.width; u += 3)
			{
				const size_t i = size_t(v) * f.width + u;
				if (!f.depthMm[i]) continue;
				valid++;
				const Eigen::Vector3d x =
				    backProject(cam, u, v, f.depthMm[i] * 1e-3, k);
				double dStatic = 1e9, dMoving = 1e9;
				for (const auto& p : prims)
					(p.objectId ? dMoving : dStatic) =
					    std::min(p.objectId ? dMoving : dStatic,
					             distanceToSurface(p, x));
				ASSERT_LT(std::min(dStatic, dMoving), 1e-3)
				    << "pixel " << u << "," << v;
				// The mask says "moving" exactly when the surface is a moving
				// one.
				if (f.mask[i])
				{
					moving++;
					EXPECT_LT(dMoving, 1e-3);
				}
				else
					EXPECT_LT(dStatic, 1e-3);
				EXPECT_EQ(f.mask[i] == 255, f.objectId[i] > 0);
			}
		EXPECT_GT(valid, size_t(0.8 * f.width * f.height / 9));
		EXPECT_GT(moving, 100u);
	}
}

TEST(Renderer, DepthNoiseFollowsTheModel)
{
	const Scene scene = pendulumScene();
	CameraParams cam;
	DepthParams clean;
	clean.makeNoiseless();
	DepthParams noisy = clean;
	noisy.noiseA = 2e-3;
	const auto k = camAt(0);
	RenderedFrame f0;
	Renderer(cam, clean, RgbParams())
	    .render(scene, 0, k.R_WC, k.p_WC, 1, 0, f0);
	// Normalised errors (z_noisy - z_true) / (a z^2): mean 0, std 1, quantised
	// to 1 mm.
	double s1 = 0, s2 = 0;
	size_t n = 0;
	for (uint64_t frame = 0; frame < 4; frame++)
	{
		RenderedFrame f;
		Renderer(cam, noisy, RgbParams())
		    .render(scene, 0, k.R_WC, k.p_WC, 9, frame, f);
		for (size_t i = 0; i < f.depthMm.size(); i++)
		{
			if (!f.depthMm[i] || !f0.depthMm[i]) continue;
			const double z = f.depthTrue[i];
			if (z < 2.0) continue;  // sigma >= 8 mm: quantisation negligible
			const double e = (f.depthMm[i] * 1e-3 - z) / (noisy.noiseA * z * z);
			s1 += e;
			s2 += e * e;
			n++;
		}
	}
	ASSERT_GT(n, 100000u);
	const double mean = s1 / n, sd = std::sqrt(s2 / n - mean * mean);
	EXPECT_NEAR(mean, 0.0, 0.01);
	EXPECT_NEAR(sd, 1.0, 0.02);
}

TEST(Renderer, NoReadingBeyondRangeOrAtGrazingAngles)
{
	Scene scene;
	RoomParams rp;
	rp.size = {12, 12, 3};
	rp.furniture = 0;
	buildRoom(rp, scene);
	CameraParams cam;
	DepthParams dp;
	const Renderer r(cam, dp, RgbParams());
	HandheldMotionParams mp;
	mp.position = {-5, 0, 0.3};
	mp.yprDeg = {0, 5,
	             0};  // low, looking along the floor: grazing within range
	const auto k = HandheldMotion(mp).at(0);
	RenderedFrame f;
	r.render(scene, 0, k.R_WC, k.p_WC, 1, 0, f);
	size_t far = 0, grazing = 0, valid = 0;
	const double cosG = std::cos(dp.grazingDeg * M_PI / 180);
	for (int v = 0; v < f.height; v++)
		for (int u = 0; u < f.width; u++)
		{
			const size_t i = size_t(v) * f.width + u;
			const double z = f.depthTrue[i];
			const Eigen::Vector3d d_W =
			    k.R_WC * Eigen::Vector3d((u - cam.cxS()) / cam.fxS(),
			                             (v - cam.cyS()) / cam.fyS(), 1);
			const Eigen::Vector3d x = k.p_WC + z * d_W;
			// Floor pixels: incidence from the normal (0,0,1)
			const bool floor = std::abs(x.z()) < 1e-6;
			if (z > dp.maxRange)
			{
				far++;
				EXPECT_EQ(f.depthMm[i], 0);
			}
			else if (floor && std::abs(d_W.z()) / d_W.norm() < cosG)
			{
				grazing++;
				EXPECT_EQ(f.depthMm[i], 0);
			}
			if (f.depthMm[i]) valid++;
		}
	EXPECT_GT(far, 1000u);
	EXPECT_GT(grazing, 100u);
	EXPECT_GT(valid, 10000u);
}

TEST(Renderer, TextureHasEnoughCornersForKlt)
{
	const Scene scene = pendulumScene();
	RgbParams rgb;
	rgb.noiseSigma = 0;
	const Renderer r(CameraParams(), DepthParams(), rgb);
	const auto k = camAt(0);
	RenderedFrame f;
	r.render(scene, 0, k.R_WC, k.p_WC, 1, 0, f);
	cv::Mat img(f.height, f.width, CV_8UC3, f.rgb.data()), grey;
	cv::cvtColor(img, grey, cv::COLOR_RGB2GRAY);
	std::vector<cv::Point2f> corners;
	cv::goodFeaturesToTrack(grey, corners, 1000, 0.01, 10);
	EXPECT_GT(corners.size(), 500u);
	// Every quarter of the image has corners.
	int quarters[4] = {0, 0, 0, 0};
	for (const auto& c : corners)
		quarters[(c.x > f.width / 2 ? 1 : 0) + (c.y > f.height / 2 ? 2 : 0)]++;
	for (int q : quarters) EXPECT_GT(q, 50);
}

TEST(Renderer, SameSeedSameFrameOtherSeedDiffers)
{
	const Scene scene = pendulumScene();
	const Renderer r{CameraParams(), DepthParams(), RgbParams()};
	const auto k = camAt(1);
	RenderedFrame a, b, c;
	r.render(scene, 1, k.R_WC, k.p_WC, 42, 3, a);
	r.render(scene, 1, k.R_WC, k.p_WC, 42, 3, b);
	r.render(scene, 1, k.R_WC, k.p_WC, 43, 3, c);
	EXPECT_EQ(a.depthMm, b.depthMm);
	EXPECT_EQ(a.rgb, b.rgb);
	EXPECT_NE(a.depthMm, c.depthMm);
	EXPECT_NE(a.rgb, c.rgb);
	EXPECT_EQ(a.mask, c.mask);
}

TEST(Renderer, ProjectorShadowLeftOfForegroundObjects)
{
	// A box 1.8 m away in front of a wall 4 m away: the band left of the box
	// where the projector (7.5 cm to the right) cannot see the wall has width
	// fx b (1/z_box - 1/z_wall) pixels; no shadow on the right.
	Scene scene;
	RoomParams rp;
	rp.size = {6, 10, 3};
	rp.furniture = 0;
	buildRoom(rp, scene);
	Primitive box;
	box.shape = Shape::Box;
	box.t_WP = {1, 0, 1.2};
	box.half = {0.2, 0.2, 0.3};
	scene.staticPrims.push_back(box);
	CameraParams cam;
	DepthParams dp;
	dp.makeNoiseless();
	HandheldMotionParams mp;
	mp.position = {-1, 0, 1.2};
	mp.yprDeg = {0, 0, 0};
	const auto k = HandheldMotion(mp).at(0);
	RenderedFrame f;
	Renderer(cam, dp, RgbParams()).render(scene, 0, k.R_WC, k.p_WC, 1, 0, f);
	const int v = int(cam.cyS());
	int uL = -1, uR = -1;
	for (int u = 0; u < f.width; u++)
		if (std::abs(f.depthTrue[v * f.width + u] - 1.8) < 1e-6)
		{
			if (uL < 0) uL = u;
			uR = u;
		}
	ASSERT_GT(uL, 20);
	ASSERT_LT(uR, f.width - 20);
	int shadow = 0;
	for (int u = uL - 1; u >= 0 && f.depthMm[v * f.width + u] == 0; u--)
		shadow++;
	const double expected =
	    cam.fxS() * dp.projectorBaseline * (1 / 1.8 - 1 / 4.0);
	EXPECT_NEAR(shadow, expected, 1.5);
	EXPECT_GT(f.depthMm[v * f.width + uR + 1], 0);  // right side lit
	EXPECT_GT(f.depthMm[v * f.width + uL], 0);      // the box itself lit
	// Without a projector baseline: no shadow.
	dp.projectorBaseline = 0;
	Renderer(cam, dp, RgbParams()).render(scene, 0, k.R_WC, k.p_WC, 1, 0, f);
	EXPECT_GT(f.depthMm[v * f.width + uL - 1], 0);
}
