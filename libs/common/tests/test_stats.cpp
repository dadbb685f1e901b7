// The one summary of a series of measurements (bims/common/stats.h).
#include <bims/common/stats.h>
#include <gtest/gtest.h>

TEST(Percentiles, MedianAndP95)
{
	std::vector<double> v;
	for (int i = 100; i >= 1; i--) v.push_back(i);
	const auto p = bims::Percentiles::of(v);
	EXPECT_DOUBLE_EQ(p.median, 51);
	EXPECT_DOUBLE_EQ(p.p95, 95);
	EXPECT_DOUBLE_EQ(p.mean, 50.5);
	EXPECT_EQ(p.n, 100u);
	// 12 values: the 95th percentile is the 12th (rank ceil(0.95 n) - 1)
	const auto q =
	    bims::Percentiles::of({12, 3, 5, 1, 2, 4, 6, 7, 8, 9, 10, 11});
	EXPECT_DOUBLE_EQ(q.median, 7);
	EXPECT_DOUBLE_EQ(q.p95, 12);
	const auto e = bims::Percentiles::of({});
	EXPECT_EQ(e.n, 0u);
	EXPECT_DOUBLE_EQ(e.median + e.p95 + e.mean, 0);
}
