// Test helper: a tiny ray-caster of textured planes (a room) and an IMU
// generator on a smooth trajectory, so that the egomotion tests have exact
// ground truth without the simulator. Fixed seeds only.
#pragma once

#include <bims/common/so3.h>
#include <bims/ego/attitude_filter.h>
#include <bims/ego/rgbd_input.h>

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

namespace bims::ego::test
{
/** Intrinsics of the tests' 320 x 240 camera (about 63 x 49 deg). */
inline Eigen::Matrix3d K320()
{
	Eigen::Matrix3d K;
	K << 262.5, 0, 159.5, 0, 262.5, 119.5, 0, 0, 1;
	return K;
}

/** Smooth value noise in [0, 255] on plane coordinates (metres). */
inline double valueNoise(double u, double v, uint32_t seed)
{
	auto hash = [seed](int64_t i, int64_t j)
	{
		uint64_t h = static_cast<uint64_t>(i) * 73856093ull ^
		             static_cast<uint64_t>(j) * 19349663ull ^
		             (seed * 83492791ull);
		h ^= h >> 13;
		h *= 0x5bd1e995ull;
		h ^= h >> 15;
		return static_cast<double>(h & 0xffff) / 65535.0;
	};
	double sum = 0, amp = 1, norm = 0, f = 1 / 0.03;  // 3 cm cells
	for (int o = 0; o < 3; o++)
	{
		const double x = u * f, y = v * f;
		const int64_t i = static_cast<int64_t>(std::floor(x)),
		              j = static_cast<int64_t>(std::floor(y));
		const double fx = x - i, fy = y - j;
		const double a = hash(i, j), b = hash(i + 1, j), c = hash(i, j + 1),
		             d = hash(i + 1, j + 1);
		sum += amp * ((1 - fy) * ((1 - fx) * a + fx * b) +
		              fy * ((1 - fx) * c + fx * d));
		norm += amp;
		amp *= 0.5;
		f *= 2.3;
	}
	return 255.0 * sum / norm;
}

struct Plane
{
	Eigen::Vector3d n;       // unit normal (world)
	double d;                // n . X = d
	Eigen::Vector3d e1, e2;  // in-plane axes for texture coordinates
	uint32_t seed;
};

/** A 8 x 6 x 3 m room seen from inside ({W}: z up). */
inline std::vector<Plane> room()
{
	using V = Eigen::Vector3d;
	return {
	    {V(1, 0, 0), 4, V(0, 1, 0), V(0, 0, 1), 1},      // front wall x = 4
	    {V(-1, 0, 0), 4, V(0, 1, 0), V(0, 0, 1), 2},     // back wall x = -4
	    {V(0, 1, 0), 3, V(1, 0, 0), V(0, 0, 1), 3},      // left wall y = 3
	    {V(0, -1, 0), 3, V(1, 0, 0), V(0, 0, 1), 4},     // right wall y = -3
	    {V(0, 0, 1), -1.2, V(1, 0, 0), V(0, 1, 0), 5},   // floor z = -1.2
	    {V(0, 0, -1), -1.8, V(1, 0, 0), V(0, 1, 0), 6},  // ceiling z = 1.8
	};
}

/** Renders grey + depth for camera pose (R_WC, p_WC). */
inline RgbdFrame render(const Eigen::Matrix3d& R_WC,
                        const Eigen::Vector3d& p_WC, const Eigen::Matrix3d& K,
                        int W, int H, double t,
                        const std::vector<Plane>& planes = room())
{
	RgbdFrame f;
	f.t = t;
	f.K = K;
	f.grey.create(H, W, CV_8UC1);
	f.depth.create(H, W, CV_32FC1);
	const Eigen::Matrix3d Kinv = K.inverse();
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
		{
			const Eigen::Vector3d rayC = Kinv * Eigen::Vector3d(u, v, 1);
			const Eigen::Vector3d rayW = R_WC * rayC;
			double best = 1e9;
			const Plane* hit = nullptr;
			for (const auto& pl : planes)
			{
				const double den = pl.n.dot(rayW);
				if (std::abs(den) < 1e-9) continue;
				const double s = (pl.d - pl.n.dot(p_WC)) / den;
				if (s > 0 && s < best)
				{
					best = s;
					hit = &pl;
				}
			}
			if (!hit)
			{
				f.grey.at<uint8_t>(v, u) = 0;
				f.depth.at<float>(v, u) = 0;
				continue;
			}
			const Eigen::Vector3d X = p_WC + best * rayW;
			f.grey.at<uint8_t>(v, u) = static_cast<uint8_t>(std::clamp(
			    valueNoise(X.dot(hit->e1), X.dot(hit->e2), hit->seed), 0.0,
			    255.0));
			f.depth.at<float>(v, u) = static_cast<float>(best);  // rayC.z = 1
		}
	return f;
}

/** Camera looking along world +x (optical z -> x, x -> -y, y -> -z). */
inline Eigen::Matrix3d R_WC_lookingNorth()
{
	Eigen::Matrix3d R;
	R.col(0) = Eigen::Vector3d(0, -1, 0);
	R.col(1) = Eigen::Vector3d(0, 0, -1);
	R.col(2) = Eigen::Vector3d(1, 0, 0);
	return R;
}

/** Trajectory: R_WC(t) = R0 Exp(w_C t), p(t) = v t (constant rates). */
struct Motion
{
	Eigen::Matrix3d R0 = R_WC_lookingNorth();
	Eigen::Vector3d w_C = Eigen::Vector3d(0.1, 0.4, 0.05);  // [rad/s]
	Eigen::Vector3d v_W = Eigen::Vector3d(0.3, 0.2, 0.05);  // [m/s]
	Eigen::Matrix3d R(double t) const { return R0 * expSO3(w_C * t); }
	Eigen::Vector3d p(double t) const { return v_W * t; }
};

/** Earth field in {W} (NWU): horizontal north, dip 60 deg down. */
inline Eigen::Vector3d magW()
{
	const double dip = 60 * M_PI / 180;
	return 0.5 * Eigen::Vector3d(std::cos(dip), 0, -std::sin(dip));
}

/** Exact IMU sample at time t for an IMU with R_WI = R_WC R_IC^T. */
inline ImuSample imuAt(const Motion& m, const Eigen::Matrix3d& R_IC, double t)
{
	ImuSample s;
	s.t = t;
	const Eigen::Matrix3d R_WI = m.R(t) * R_IC.transpose();
	s.hasGyro = s.hasAcc = s.hasMag = true;
	s.gyro = R_IC * m.w_C;
	s.acc = R_WI.transpose() * Eigen::Vector3d(0, 0, 9.80665);
	s.mag = R_WI.transpose() * magW();
	return s;
}

}  // namespace bims::ego::test
