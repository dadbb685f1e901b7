// Scene geometry for the simulator: analytic primitives (boxes, spheres and the
// room, an inside-out box) in the world frame {W} (z up, x north), and the
// moving objects built from them.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace bims::sim
{
/** Kind of analytic primitive. */
enum class Shape : uint8_t
{
	Box,     ///< solid box, seen from outside; half extents `half` [m]
	Sphere,  ///< solid sphere of radius half.x() [m]
	Room     ///< hollow box seen from inside (floor, ceiling, walls)
};

/** One primitive placed in the world at time t. Its own frame {P} is centred
 * on the primitive, axes along the box edges. */
struct Primitive
{
	Shape shape = Shape::Box;
	Eigen::Matrix3d R_WP =
	    Eigen::Matrix3d::Identity();  ///< orientation of {P} in {W}
	Eigen::Vector3d t_WP =
	    Eigen::Vector3d::Zero();  ///< centre of {P} in {W} [m]
	Eigen::Vector3d half =
	    Eigen::Vector3d::Ones();  ///< half extents [m] (sphere: radius in x)
	int objectId = 0;             ///< 0 = static scene, k > 0 = moving object k
	uint32_t texture = 0;         ///< seed of the procedural texture
	double cell = 0.2;            ///< texture cell size [m]
};

/** A ray hit on a primitive. */
struct SurfaceHit
{
	Eigen::Vector3d n_W;  ///< unit outward (room: inward) normal in {W}
	double s = 0, t = 0;  ///< texture coordinates on the surface [m]
	int face = 0;         ///< face index (boxes: 0..5), 0 for spheres
};

/** Ray parameter of the first hit of o + lambda d (o, d in {P}) with the
 * primitive, lambda > 0, or +inf when there is none. */
double intersectLocal(const Primitive& p, const Eigen::Vector3d& o_P,
                      const Eigen::Vector3d& d_P);

/** Normal and texture coordinates at a point x_P on the primitive's surface
 * (in {P}). */
SurfaceHit surfaceAt(const Primitive& p, const Eigen::Vector3d& x_P);

/** Unsigned distance [m] from a world point to the primitive's surface. */
double distanceToSurface(const Primitive& p, const Eigen::Vector3d& x_W);

/** Something that moves independently of the camera. */
class MovingObject
{
 public:
	virtual ~MovingObject() = default;
	/** Name from the .ini section ("pendulum", "walker2", ...). */
	virtual const std::string& name() const = 0;
	/** Root pose of the object at time t [s since the sequence start]:
	 * rotation R_WO and translation t_WO. */
	virtual void pose(double t, Eigen::Matrix3d& R_WO,
	                  Eigen::Vector3d& t_WO) const = 0;
	/** Appends the object's primitives at time t, with objectId = \a id. */
	virtual void primitives(double t, int id,
	                        std::vector<Primitive>& out) const = 0;
};

/** The room, its furniture and the moving objects. */
struct Scene
{
	std::vector<Primitive> staticPrims;  ///< room + furniture (objectId 0)
	std::vector<std::unique_ptr<MovingObject>> objects;  ///< ids 1..N in order
	/** All primitives at time t [s]: static first, then each object's. */
	std::vector<Primitive> primitivesAt(double t) const;
	/** Distance [m] from a world point to the nearest surface at time t. */
	double distanceToNearestSurface(const Eigen::Vector3d& x_W, double t) const;
};

}  // namespace bims::sim
