// Weighted least squares in six unknowns (a rigid motion's twist), as the
// dense alignment builds it pass after pass: the normal equations from the
// residuals, and Tukey's biweight that weights them.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace bims::ego
{
/** H = sum w J^T J and b = sum w J^T r over residuals r with Jacobians J
 * (1 x 6) and weights w. The residuals are kept as the rows
 * sqrt(w) [J, r, 0] and summed by one matrix product (Eigen's rank update,
 * vectorised) when asked: faster than 27 multiply-adds into memory per
 * residual. Reuse one object from pass to pass (clear()): its rows keep
 * their memory. */
class NormalEquations6
{
 public:
	using Mat6 = Eigen::Matrix<double, 6, 6>;
	using Vec6 = Eigen::Matrix<double, 6, 1>;

	void clear() { n_ = 0; }
	std::size_t size() const { return n_; }

	/** Adds the residual \a r with Jacobian \a J (6 values) and weight
	 * rootW^2 (the caller often has the weight's square root at hand:
	 * Tukey::s). */
	void add(const float* J, double rootW, double r)
	{
		if (rows_.size() < (n_ + 1) * kCols)
			rows_.resize(std::max((n_ + 1) * kCols, 2 * rows_.size()));
		double* o = rows_.data() + n_ * kCols;
		for (int i = 0; i < 6; i++) o[i] = rootW * J[i];
		o[6] = rootW * r;
		o[7] = 0;
		++n_;
	}

	/** H and b of the residuals added since clear() (zero without any). */
	void get(Mat6& H, Vec6& b) const
	{
		H.setZero();
		b.setZero();
		if (n_ == 0) return;
		const Eigen::Map<
		    const Eigen::Matrix<double, Eigen::Dynamic, kCols, Eigen::RowMajor>>
		    M(rows_.data(), Eigen::Index(n_), kCols);
		// the lower triangle of M^T M (its upper one stays zero)
		Eigen::Matrix<double, kCols, kCols> G =
		    Eigen::Matrix<double, kCols, kCols>::Zero();
		G.selfadjointView<Eigen::Lower>().rankUpdate(M.transpose());
		H = G.topLeftCorner<6, 6>().selfadjointView<Eigen::Lower>();
		b = G.block<1, 6>(6, 0).transpose();
	}

 private:
	static constexpr std::size_t kCols = 8;
	std::vector<double> rows_;
	std::size_t n_ = 0;
};

/** Tukey's biweight at the scaled residual a = e / c: s = 1 - a^2 (0 at
 * and beyond |a| = 1), whose square is the weight (so s is the weight's
 * square root, NormalEquations6::add's rootW), and the loss
 * rho = c^2 / 6 (1 - s^3) (c^2 / 6 at and beyond c). */
struct Tukey
{
	double s, loss;

	static Tukey at(double a, double c)
	{
		const double s = 1 - a * a;
		if (s <= 0) return {0, c * c / 6};
		return {s, c * c / 6 * (1 - s * s * s)};
	}
};

}  // namespace bims::ego
