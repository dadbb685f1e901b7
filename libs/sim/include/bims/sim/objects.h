// The room and the independently moving objects of the simulator, each with a
// plain parameter struct read from its own .ini section. All positions are in
// the world frame {W} (z up, x north, floor at z = 0) in metres; angles in the
// .ini are degrees.
#pragma once

#include <bims/sim/scene.h>
#include <mrpt/config/CConfigFileBase.h>

namespace bims::sim
{
/** [room]: a textured box room with furniture boxes along the walls. */
struct RoomParams
{
	Eigen::Vector3d size{
	    5.5, 5.0, 2.8};  ///< x, y, z extent [m]; floor at z=0, centred on x=y=0
	int furniture = 6;  ///< number of furniture boxes (placed from layout_seed)
	uint64_t layoutSeed =
	    1;  ///< seed of the furniture layout (independent of --seed)
	double wallCell = 0.30;  ///< texture cell size on walls, floor, ceiling [m]
	double furnitureCell = 0.12;  ///< texture cell on furniture [m]
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section);
};

/** Appends the room and its furniture to scene.staticPrims. */
void buildRoom(const RoomParams& p, Scene& scene);

/** [pendulum*]: a rod with a ball, swinging about a horizontal axis (the
 * paper's experiment). Angle theta(t) = amplitude cos(2 pi t / period + phase).
 */
struct PendulumParams
{
	Eigen::Vector3d pivot{0.6, 0.0, 2.2};  ///< pivot point in {W} [m]
	double length = 1.2;                   ///< pivot to ball centre [m]
	double amplitudeDeg = 30;              ///< swing amplitude [deg]
	double periodS = 0;      ///< period [s]; 0 = ideal pendulum 2 pi sqrt(L/g)
	double phaseDeg = 0;     ///< phase at t=0 [deg]
	double azimuthDeg = 90;  ///< swing direction in the horizontal plane (0 =
	                         ///< +x north, 90 = +y west) [deg]
	double ballRadius = 0.15;  ///< [m]
	double rodWidth = 0.03;    ///< square rod side [m]
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section);
};

/** [box*]: a box sliding on the floor back and forth along a line,
 * position = centre + dir * amplitude * sin(2 pi t / period + phase). */
struct SlidingBoxParams
{
	Eigen::Vector2d center{0.8,
	                       0.0};  ///< centre of the motion on the floor [m]
	Eigen::Vector3d size{0.5, 0.4, 0.45};  ///< box extent [m]
	double azimuthDeg = 90;  ///< direction of motion (0 = +x) [deg]
	double amplitude = 0.8;  ///< half the travel [m]
	double periodS = 6;      ///< [s]
	double phaseDeg = 0;     ///< [deg]
	double yawDeg = 0;       ///< box heading [deg]
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section);
};

/** [walker*]: a person-sized body (legs, torso, arms, head) walking on a
 * circle at constant speed, limbs swinging with the gait. */
struct WalkerParams
{
	Eigen::Vector2d center{0.8, 0.0};  ///< circle centre on the floor [m]
	double radius = 1.0;               ///< circle radius [m]
	double speed = 0.8;    ///< walking speed [m/s]; negative = clockwise
	double phaseDeg = 0;   ///< angle on the circle at t=0 [deg]
	double height = 1.75;  ///< body height [m]
	double swingDeg = 25;  ///< leg swing amplitude [deg]
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section);
};

std::unique_ptr<MovingObject> makePendulum(const std::string& name,
                                           const PendulumParams& p);
std::unique_ptr<MovingObject> makeSlidingBox(const std::string& name,
                                             const SlidingBoxParams& p);
std::unique_ptr<MovingObject> makeWalker(const std::string& name,
                                         const WalkerParams& p);

}  // namespace bims::sim
