// Deterministic random numbers for the simulator: the same seed gives the same
// sequence on every machine and compiler (no std::*_distribution, whose output
// is implementation-defined).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace bims::sim
{
/** SplitMix64 step: mixes a 64-bit state into a well-distributed value. Used to
 * seed Rng and to derive independent streams from (seed, stream id). */
inline uint64_t splitmix64(uint64_t& state)
{
	uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
	z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
	z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
	return z ^ (z >> 31);
}

/** A stateless hash of up to four integers to 64 bits (procedural textures,
 * per-object layout). */
inline uint64_t hash64(uint64_t a, uint64_t b = 0, uint64_t c = 0,
                       uint64_t d = 0)
{
	uint64_t s = a * 0xD1B54A32D192ED03ULL;
	s ^= splitmix64(s) + b;
	s ^= splitmix64(s) + c;
	s ^= splitmix64(s) + d;
	return splitmix64(s);
}

/** xoshiro256** generator with a portable Box-Muller Gaussian. */
class Rng
{
 public:
	/** Seeds from (seed, stream): different streams are independent, so e.g.
	 * the depth noise of frame k does not depend on how many IMU samples were
	 * drawn before it. */
	explicit Rng(uint64_t seed, uint64_t stream = 0)
	{
		uint64_t sm = hash64(seed, stream);
		for (auto& x : s_) x = splitmix64(sm);
	}
	/** Next raw 64-bit value. */
	uint64_t next()
	{
		const uint64_t result = rotl(s_[1] * 5, 7) * 9;
		const uint64_t t = s_[1] << 17;
		s_[2] ^= s_[0];
		s_[3] ^= s_[1];
		s_[1] ^= s_[2];
		s_[0] ^= s_[3];
		s_[2] ^= t;
		s_[3] = rotl(s_[3], 45);
		return result;
	}
	/** Uniform in [0, 1). */
	double uniform() { return double(next() >> 11) * 0x1.0p-53; }
	/** Uniform in [a, b). */
	double uniform(double a, double b) { return a + (b - a) * uniform(); }
	/** Standard normal N(0, 1) (Box-Muller, both values used). */
	double gauss()
	{
		if (hasSpare_)
		{
			hasSpare_ = false;
			return spare_;
		}
		double u1 = uniform();
		while (u1 <= 0.0) u1 = uniform();
		const double u2 = uniform();
		const double r = std::sqrt(-2.0 * std::log(u1));
		const double a = 2.0 * M_PI * u2;
		spare_ = r * std::sin(a);
		hasSpare_ = true;
		return r * std::cos(a);
	}

	/** Approximate standard normal from one draw: inverse-CDF table (4096
	 * intervals, linear interpolation; tails cut at 3.7 sigma). Several times
	 * faster than gauss(); for image noise, not for statistics-critical use. */
	double gaussFast()
	{
		const double* tab = normalQuantileTable();
		const uint64_t r = next();
		const unsigned i = unsigned(r >> 52);  // 12 bits
		const double f = double((r >> 28) & 0xFFFFFF) * 0x1.0p-24;
		return tab[i] + f * (tab[i + 1] - tab[i]);
	}

 private:
	/** Phi^-1 at (i + 0.5) / 4097, i = 0..4096 (computed once by bisection). */
	static const double* normalQuantileTable()
	{
		static const auto table = []
		{
			std::array<double, 4097> t{};
			for (size_t i = 0; i < t.size(); i++)
			{
				const double p = (double(i) + 0.5) / double(t.size());
				double lo = -10, hi = 10;
				for (int it = 0; it < 60; it++)
				{
					const double mid = 0.5 * (lo + hi);
					(0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) =
					    mid;
				}
				t[i] = 0.5 * (lo + hi);
			}
			return t;
		}();
		return table.data();
	}
	static uint64_t rotl(uint64_t x, int k)
	{
		return (x << k) | (x >> (64 - k));
	}
	uint64_t s_[4];
	double spare_ = 0;
	bool hasSpare_ = false;
};

}  // namespace bims::sim
