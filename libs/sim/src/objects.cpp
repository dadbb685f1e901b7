#include <bims/common/config.h>
#include <bims/common/frames.h>
#include <bims/sim/objects.h>
#include <bims/sim/rng.h>
#include "ini_vector.h"

#include <cmath>

namespace bims::sim
{
using detail::kDeg;
using detail::vec3;
namespace
{

Eigen::Matrix3d rotZ(double a)
{
	return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

Primitive box(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
              const Eigen::Vector3d& half, uint32_t tex, double cell,
              int id = 0)
{
	Primitive p;
	p.shape = Shape::Box;
	p.R_WP = R;
	p.t_WP = t;
	p.half = half;
	p.texture = tex;
	p.cell = cell;
	p.objectId = id;
	return p;
}
uint32_t texSeed(const std::string& name, uint32_t part)
{
	uint64_t h = 1469598103934665603ULL;
	for (char c : name) h = (h ^ uint8_t(c)) * 1099511628211ULL;
	return uint32_t(hash64(h, part));
}

class Pendulum : public MovingObject
{
 public:
	Pendulum(std::string name, const PendulumParams& p)
	    : name_(std::move(name)), p_(p)
	{
		period_ = p.periodS > 0 ? p.periodS
		                        : 2 * M_PI * std::sqrt(p.length / kGravity);
		const Eigen::Vector3d dir(std::cos(p.azimuthDeg * kDeg),
		                          std::sin(p.azimuthDeg * kDeg), 0);
		axis_ = dir.cross(
		    Eigen::Vector3d::UnitZ());  // +theta moves the ball towards dir
	}
	const std::string& name() const override { return name_; }
	double angle(double t) const
	{
		return p_.amplitudeDeg * kDeg *
		       std::cos(2 * M_PI * t / period_ + p_.phaseDeg * kDeg);
	}
	void pose(double t, Eigen::Matrix3d& R, Eigen::Vector3d& x) const override
	{
		R = Eigen::AngleAxisd(angle(t), axis_).toRotationMatrix();
		x = p_.pivot;
	}
	void primitives(double t, int id,
	                std::vector<Primitive>& out) const override
	{
		Eigen::Matrix3d R;
		Eigen::Vector3d x;
		pose(t, R, x);
		const double w = 0.5 * p_.rodWidth;
		const double rodLen = std::max(0.0, p_.length - p_.ballRadius);
		out.push_back(box(R, x + R * Eigen::Vector3d(0, 0, -0.5 * rodLen),
		                  {w, w, 0.5 * rodLen}, texSeed(name_, 0), 0.05, id));
		Primitive ball;
		ball.shape = Shape::Sphere;
		ball.R_WP = R;
		ball.t_WP = x + R * Eigen::Vector3d(0, 0, -p_.length);
		ball.half = Eigen::Vector3d::Constant(p_.ballRadius);
		ball.texture = texSeed(name_, 1);
		ball.cell = 0.06;
		ball.objectId = id;
		out.push_back(ball);
	}

 private:
	std::string name_;
	PendulumParams p_;
	double period_;
	Eigen::Vector3d axis_;
};

class SlidingBox : public MovingObject
{
 public:
	SlidingBox(std::string name, const SlidingBoxParams& p)
	    : name_(std::move(name)), p_(p)
	{
	}
	const std::string& name() const override { return name_; }
	void pose(double t, Eigen::Matrix3d& R, Eigen::Vector3d& x) const override
	{
		const double s = p_.amplitude * std::sin(2 * M_PI * t / p_.periodS +
		                                         p_.phaseDeg * kDeg);
		const double az = p_.azimuthDeg * kDeg;
		R = rotZ(p_.yawDeg * kDeg);
		x = Eigen::Vector3d(p_.center.x() + s * std::cos(az),
		                    p_.center.y() + s * std::sin(az),
		                    0.5 * p_.size.z());
	}
	void primitives(double t, int id,
	                std::vector<Primitive>& out) const override
	{
		Eigen::Matrix3d R;
		Eigen::Vector3d x;
		pose(t, R, x);
		out.push_back(box(R, x, 0.5 * p_.size, texSeed(name_, 0), 0.08, id));
	}

 private:
	std::string name_;
	SlidingBoxParams p_;
};

class Walker : public MovingObject
{
 public:
	Walker(std::string name, const WalkerParams& p)
	    : name_(std::move(name)), p_(p)
	{
	}
	const std::string& name() const override { return name_; }
	/** Root frame: on the floor between the feet, x forward, z up. */
	void pose(double t, Eigen::Matrix3d& R, Eigen::Vector3d& x) const override
	{
		const double ang = p_.phaseDeg * kDeg + p_.speed * t / p_.radius;
		x = Eigen::Vector3d(p_.center.x() + p_.radius * std::cos(ang),
		                    p_.center.y() + p_.radius * std::sin(ang), 0);
		const double heading = ang + (p_.speed >= 0 ? M_PI / 2 : -M_PI / 2);
		R = rotZ(heading);
	}
	void primitives(double t, int id,
	                std::vector<Primitive>& out) const override
	{
		Eigen::Matrix3d R;
		Eigen::Vector3d x;
		pose(t, R, x);
		const double k = p_.height / 1.75;  // scale of a 1.75 m body
		const double stride = 1.4 * k;      // two steps [m]
		const double gait = 2 * M_PI * std::abs(p_.speed) * t / stride;
		const double swing = p_.swingDeg * kDeg * std::sin(gait);
		const double hipZ = 0.9 * k, legLen = 0.88 * k;
		auto limb = [&](double y, double z0, double len, double ang, double w,
		                uint32_t part)
		{
			// A limb hanging from a joint at (0, y, z0), rotated about the body
			// y axis.
			const Eigen::Matrix3d Rl =
			    R * Eigen::AngleAxisd(ang, Eigen::Vector3d::UnitY())
			            .toRotationMatrix();
			const Eigen::Vector3d joint = x + R * Eigen::Vector3d(0, y, z0);
			out.push_back(box(
			    Rl, joint + Rl * Eigen::Vector3d(0, 0, -0.5 * len),
			    {0.5 * w, 0.5 * w, 0.5 * len}, texSeed(name_, part), 0.07, id));
		};
		limb(0.1 * k, hipZ, legLen, swing, 0.14 * k, 0);
		limb(-0.1 * k, hipZ, legLen, -swing, 0.14 * k, 0);
		out.push_back(box(R, x + R * Eigen::Vector3d(0, 0, hipZ + 0.3 * k),
		                  Eigen::Vector3d(0.12, 0.21, 0.31) * k,
		                  texSeed(name_, 1), 0.08, id));
		limb(0.27 * k, 1.45 * k, 0.62 * k, -0.8 * swing, 0.08 * k, 2);
		limb(-0.27 * k, 1.45 * k, 0.62 * k, 0.8 * swing, 0.08 * k, 2);
		Primitive head;
		head.shape = Shape::Sphere;
		head.R_WP = R;
		head.t_WP = x + R * Eigen::Vector3d(0, 0, 1.62 * k);
		head.half = Eigen::Vector3d::Constant(0.11 * k);
		head.texture = texSeed(name_, 3);
		head.cell = 0.05;
		head.objectId = id;
		out.push_back(head);
	}

 private:
	std::string name_;
	WalkerParams p_;
};
}  // namespace

void RoomParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                    const std::string& section)
{
	ConfigSection s(cfg, section);
	size = vec3(
	    s.getDoubles("size", {size.x(), size.y(), size.z()}, 3, 1.0, 100.0));
	furniture = int(s.getInt("furniture", furniture, 0, 50));
	layoutSeed =
	    uint64_t(s.getInt("layout_seed", long(layoutSeed), 0, 1L << 40));
	wallCell = s.getDouble("wall_cell", wallCell, 0.01, 5.0);
	furnitureCell = s.getDouble("furniture_cell", furnitureCell, 0.01, 5.0);
	s.finish();
}

void buildRoom(const RoomParams& p, Scene& scene)
{
	Primitive room;
	room.shape = Shape::Room;
	room.t_WP = Eigen::Vector3d(0, 0, 0.5 * p.size.z());
	room.half = 0.5 * p.size;
	room.texture = uint32_t(hash64(p.layoutSeed, 1000));
	room.cell = p.wallCell;
	scene.staticPrims.push_back(room);

	Rng rng(p.layoutSeed, 77);
	for (int i = 0; i < p.furniture; i++)
	{
		// A box against one of the four walls, its long side along the wall.
		const int wall = int(rng.next() % 4);
		const Eigen::Vector3d ext(rng.uniform(0.6, 1.4), rng.uniform(0.35, 0.7),
		                          rng.uniform(0.4, 1.9));
		const double along = 0.5 * (wall < 2 ? p.size.y() : p.size.x());
		const double pos =
		    rng.uniform(-along + 0.5 * ext.x(), along - 0.5 * ext.x());
		const double yaw = (wall < 2 ? M_PI / 2 : 0.0);
		Eigen::Vector3d c;
		const double off = 0.5 * ext.y() + 0.02;
		switch (wall)
		{
			case 0:
				c = {0.5 * p.size.x() - off, pos, 0};
				break;
			case 1:
				c = {-0.5 * p.size.x() + off, pos, 0};
				break;
			case 2:
				c = {pos, 0.5 * p.size.y() - off, 0};
				break;
			default:
				c = {pos, -0.5 * p.size.y() + off, 0};
				break;
		}
		c.z() = 0.5 * ext.z();
		scene.staticPrims.push_back(
		    box(rotZ(yaw), c, 0.5 * ext,
		        uint32_t(hash64(p.layoutSeed, 2000 + i)), p.furnitureCell));
	}
}

void PendulumParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	ConfigSection s(cfg, section);
	pivot = vec3(
	    s.getDoubles("pivot", {pivot.x(), pivot.y(), pivot.z()}, 3, -100, 100));
	length = s.getDouble("length", length, 0.05, 20);
	amplitudeDeg = s.getDouble("amplitude_deg", amplitudeDeg, 0, 89);
	periodS = s.getDouble("period_s", periodS, 0, 1000);
	phaseDeg = s.getDouble("phase_deg", phaseDeg, -360, 360);
	azimuthDeg = s.getDouble("azimuth_deg", azimuthDeg, -360, 360);
	ballRadius = s.getDouble("ball_radius", ballRadius, 0.01, 5);
	rodWidth = s.getDouble("rod_width", rodWidth, 0.001, 1);
	if (ballRadius >= length)
		s.fail("ball_radius", "must be smaller than length");
	s.finish();
}

void SlidingBoxParams::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section)
{
	ConfigSection s(cfg, section);
	const auto c =
	    s.getDoubles("center", {center.x(), center.y()}, 2, -100, 100);
	center = {c[0], c[1]};
	size =
	    vec3(s.getDoubles("size", {size.x(), size.y(), size.z()}, 3, 0.01, 20));
	azimuthDeg = s.getDouble("azimuth_deg", azimuthDeg, -360, 360);
	amplitude = s.getDouble("amplitude", amplitude, 0, 50);
	periodS = s.getDouble("period_s", periodS, 0.1, 1000);
	phaseDeg = s.getDouble("phase_deg", phaseDeg, -360, 360);
	yawDeg = s.getDouble("yaw_deg", yawDeg, -360, 360);
	s.finish();
}

void WalkerParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section)
{
	ConfigSection s(cfg, section);
	const auto c =
	    s.getDoubles("center", {center.x(), center.y()}, 2, -100, 100);
	center = {c[0], c[1]};
	radius = s.getDouble("radius", radius, 0.1, 100);
	speed = s.getDouble("speed", speed, -5, 5);
	phaseDeg = s.getDouble("phase_deg", phaseDeg, -360, 360);
	height = s.getDouble("height", height, 0.3, 3);
	swingDeg = s.getDouble("swing_deg", swingDeg, 0, 80);
	s.finish();
}

std::unique_ptr<MovingObject> makePendulum(const std::string& n,
                                           const PendulumParams& p)
{
	return std::make_unique<Pendulum>(n, p);
}
std::unique_ptr<MovingObject> makeSlidingBox(const std::string& n,
                                             const SlidingBoxParams& p)
{
	return std::make_unique<SlidingBox>(n, p);
}
std::unique_ptr<MovingObject> makeWalker(const std::string& n,
                                         const WalkerParams& p)
{
	return std::make_unique<Walker>(n, p);
}

}  // namespace bims::sim
