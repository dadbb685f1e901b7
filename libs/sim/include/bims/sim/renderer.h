// CPU ray-casting renderer: registered depth + RGB + moving-object mask of a
// Scene seen by a pinhole camera (no distortion), with a Kinect-like depth
// noise model.
#pragma once

#include <bims/sim/motion.h>
#include <bims/sim/scene.h>
#include <mrpt/config/CConfigFileBase.h>

#include <cstdint>
#include <string>
#include <vector>

namespace bims::sim
{
/** [camera]: pinhole intrinsics. fx, fy, cx, cy are given for 640x480 and
 * scaled to the chosen resolution (cx' = (cx + 0.5) s - 0.5). Pixel (u, v)
 * (integers, from the top-left pixel centre) sees the ray
 * ((u - cx)/fx, (v - cy)/fy, 1) in {C}, as MRPT unprojects. */
struct CameraParams
{
	int width = 640, height = 480;  ///< image size [px]: 640x480 or 320x240
	double fx = 525, fy = 525, cx = 319.5, cy = 239.5;  ///< at 640x480 [px]
	/** Intrinsics at the chosen resolution [px]. */
	double fxS() const { return fx * width / 640.0; }
	double fyS() const { return fy * height / 480.0; }
	double cxS() const { return (cx + 0.5) * width / 640.0 - 0.5; }
	double cyS() const { return (cy + 0.5) * height / 480.0 - 0.5; }
	/** Sets width/height from "640x480" or "320x240"; throws
	 * std::invalid_argument otherwise. */
	void setResolution(const std::string& wxh);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section);
};

/** [depth]: Kinect-like depth sensor model. */
struct DepthParams
{
	double maxRange = 4.5;   ///< no reading beyond [m]
	double minRange = 0.4;   ///< no reading below [m]
	double noiseA = 1.5e-3;  ///< sigma(z) = noiseA * z^2 [1/m] (1.5 mm at 1 m,
	                         ///< 3 cm at 4.5 m)
	double grazingDeg =
	    80;  ///< no reading when the incidence angle exceeds this [deg]
	double dropout = 0.002;   ///< probability of a missing single pixel
	double holesPerMpx = 50;  ///< small round holes per megapixel per frame
	double holeRadiusPx = 3;  ///< maximum hole radius at 640x480 [px]
	/** Structured-light projector to the right (+x of {C}) of the depth camera
	 * [m]; surfaces it cannot see get no reading (the shadow band left of
	 * foreground objects in Kinect images). 0 = no shadows. */
	double projectorBaseline = 0.075;
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section);
	/** No noise, no dropout, no holes (range and grazing limits kept). */
	void makeNoiseless() { noiseA = dropout = holesPerMpx = 0; }
};

/** [rgb]: shading and image noise. */
struct RgbParams
{
	/** false: depth only, the scans carry no intensity image (a phone's
	 * LiDAR without its video, a time-of-flight camera). */
	bool enabled = true;
	double noiseSigma = 2.0;  ///< white noise per channel [grey levels]
	double ambient = 0.45;    ///< ambient light fraction
	Eigen::Vector3d lightDir_W{0.4, 0.3,
	                           0.87};  ///< direction towards the light in {W}
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section);
};

/** One rendered frame, row-major (index v * width + u). */
struct RenderedFrame
{
	int width = 0, height = 0;
	std::vector<float> depthTrue;   ///< noiseless depth along the optical axis
	                                ///< [m]; 0 = no surface
	std::vector<uint16_t> depthMm;  ///< sensor depth [mm], 0 = no reading
	std::vector<uint8_t> rgb;       ///< RGB, 3 bytes per pixel
	std::vector<uint8_t> mask;  ///< 255 where the visible surface belongs to a
	                            ///< moving object, else 0
	std::vector<uint8_t> objectId;  ///< 0 = static, k = moving object k
};

class Rng;

class Renderer
{
 public:
	Renderer(const CameraParams& cam, const DepthParams& depth,
	         const RgbParams& rgb);
	/** Renders the scene at time t [s] from camera pose (R_WC, p_WC). Noise
	 * draws from the random stream (seed, frameIndex). */
	void render(const Scene& scene, double t, const Eigen::Matrix3d& R_WC,
	            const Eigen::Vector3d& p_WC, uint64_t seed, uint64_t frameIndex,
	            RenderedFrame& out) const;

 private:
	/** The nearest surface per pixel (render()'s first pass). */
	struct Hits;
	/** The screen rectangle [u0, u1] x [v0, v1] of the projected bounding
	 * box of \a pr (seen from o_P with R_PC); false if off the image. The
	 * whole image for a room, or for a box partly behind the camera. */
	bool screenRect(const Primitive& pr, const Eigen::Matrix3d& R_PC,
	                const Eigen::Vector3d& o_P, int rect[4]) const;
	/** Pass 1: the nearest hit per pixel, each primitive tested only inside
	 * its screenRect(). */
	void nearestHits(const std::vector<Primitive>& prims,
	                 const Eigen::Matrix3d& R_WC, const Eigen::Vector3d& p_WC,
	                 Hits& h) const;
	/** Pass 2: shading and the depth sensor's model (noise from \a rng). */
	void shadeAndSense(const std::vector<Primitive>& prims, const Hits& h,
	                   const Eigen::Matrix3d& R_WC, Rng& rng,
	                   RenderedFrame& out) const;
	/** The projector's shadows in the depth (projector_baseline > 0). */
	void projectorShadows(const Hits& h, RenderedFrame& out) const;
	/** Small round holes in the depth. */
	void depthHoles(Rng& rng, RenderedFrame& out) const;

	CameraParams cam_;
	DepthParams depth_;
	RgbParams rgb_;
	std::vector<double> xn_,
	    yn_;  // normalised ray coordinates per column / row
};

}  // namespace bims::sim
