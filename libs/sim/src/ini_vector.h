// The simulator's .ini 3-vectors (lists of three numbers read with
// ConfigSection::getDoubles) and its degree constant: one home for the
// sources of libs/sim. Private to the library.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace bims::sim::detail
{
constexpr double kDeg = M_PI / 180.0;

inline Eigen::Vector3d vec3(const std::vector<double>& v)
{
	return {v[0], v[1], v[2]};
}

inline std::vector<double> stdv(const Eigen::Vector3d& v)
{
	return {v.x(), v.y(), v.z()};
}
}  // namespace bims::sim::detail
