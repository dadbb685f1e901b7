#include <bims/common/rounding.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

TEST(RoundHalfAway, EqualsLroundOnHalvesNeighboursAndRandomValues)
{
	// halves, the doubles next to them, zero's neighbours, large values
	for (double base : {0.0, 1.0, 2.0, 7.0, 639.0, 4095.0, 1e6,
	                    4503599627370495.0, 4503599627370496.0, 1e17, 4.6e18})
		for (double h : {0.0, 0.5, 1.0, 1.5})
			for (double s : {1.0, -1.0})
			{
				const double x = s * (base + h);
				for (double y :
				     {x, std::nextafter(x, 0.0), std::nextafter(x, INFINITY),
				      std::nextafter(x, -INFINITY)})
					ASSERT_EQ(bims::roundHalfAway(y), std::lround(y)) << y;
			}
	ASSERT_EQ(bims::roundHalfAway(0.49999999999999994), 0);
	ASSERT_EQ(bims::roundHalfAway(-0.5), -1);
	ASSERT_EQ(bims::roundHalfAway(2.5), 3);
	std::mt19937_64 rng(3);
	std::uniform_real_distribution<double> u(-5000, 5000);
	for (int i = 0; i < 200000; i++)
	{
		const double x = u(rng);
		ASSERT_EQ(bims::roundHalfAway(x), std::lround(x)) << x;
	}
}
