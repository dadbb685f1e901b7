// Tier 0: the miss update for decay = frustum (decay = raycast:
// COccupancyBayesGrid_raycast.cpp).
#include <bims/common/rounding.h>
#include <bims/maps/COccupancyBayesGrid.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace bims::maps
{

// decay = frustum. The per-cell rule (a cell decays iff its centre is in
// front of the camera, projects into the image, onto a measured depth d,
// and lies wholly in front of it: z + half diagonal < d) is applied to
// every stored cell of the blocks near the view, but whole boxes of cells
// are decided at once where the rule provably gives one answer for all of
// them: the camera coordinates of a cell are affine in its indices, so the
// centres of a box lie between those of its corners, and its pixels in the
// rectangle spanned by the corners' projections; the depths of that
// rectangle are bounded by per-tile minima and maxima of the depth image.
// Boxes with no decaying cell are skipped, boxes where every cell decays
// are decayed without projection, the others are split into octants (down
// to 4^3 cells) or decided cell by cell. The camera coordinates are formed
// from per-axis products, the same floating-point operations as for one
// cell alone, so the decisions are those of the plain rule, bit for bit.
namespace
{
// Per tile of kTilePx^2 pixels of the depth image: its bounds.
constexpr int kTilePx = 8;
// Margins of the box decisions: far larger than the rounding of the
// coordinates (~1e-14 m) and of the projections (~1e-12 px).
constexpr double kZMargin = 1e-7;

/** The side planes of the frustum in {C} (through the origin), normalised. */
struct FrustumSides
{
	double n[4][3];
};

FrustumSides frustumSides(const sensors::PinholeCamera& K)
{
	FrustumSides p{{{1, 0, (K.cx + 0.5) / K.fx},
	                {-1, 0, (K.width - 0.5 - K.cx) / K.fx},
	                {0, 1, (K.cy + 0.5) / K.fy},
	                {0, -1, (K.height - 0.5 - K.cy) / K.fy}}};
	for (auto& pl : p.n)
	{
		const double n =
		    std::sqrt(pl[0] * pl[0] + pl[1] * pl[1] + pl[2] * pl[2]);
		for (auto& v : pl) v /= n;
	}
	return p;
}

/** Per-tile bounds of a depth image (the grid's scratch, reused). */
struct DepthTiles
{
	const float* max;     ///< largest depth
	const float* minPos;  ///< smallest non-zero depth (+inf if none)
	const uint8_t* zero;  ///< whether a pixel has no depth
	int tw;               ///< tiles per row
};

/** Fills the per-tile bounds of the W x H image \a depth into the scratch
 * vectors (resized, no allocation once they are large enough). */
DepthTiles fillDepthTiles(const std::vector<float>& depth, int W, int H,
                          std::vector<float>& tileMax,
                          std::vector<float>& tileMinPos,
                          std::vector<uint8_t>& tileZero)
{
	const int tw = (W + kTilePx - 1) / kTilePx,
	          th = (H + kTilePx - 1) / kTilePx;
	tileMax.assign(size_t(tw) * th, 0.f);
	tileMinPos.assign(size_t(tw) * th, INFINITY);
	tileZero.assign(size_t(tw) * th, 0);
	for (int v = 0; v < H; ++v)
	{
		const float* row = depth.data() + size_t(v) * W;
		const size_t t0 = size_t(v / kTilePx) * tw;
		for (int u = 0; u < W; ++u)
		{
			const float d = row[u];
			const size_t ti = t0 + size_t(u / kTilePx);
			tileMax[ti] = std::max(tileMax[ti], d);
			if (d > 0)
				tileMinPos[ti] = std::min(tileMinPos[ti], d);
			else
				tileZero[ti] = 1;
		}
	}
	return {tileMax.data(), tileMinPos.data(), tileZero.data(), tw};
}

/** Whether the block with origin \a o (D^3 cells of side \a s) may hold a
 * cell in the frustum: its centre within its radius of the depth range and
 * of the inner side of every side plane. */
bool blockNearView(const VoxelKey& o, int D, double s,
                   const mrpt::math::CMatrixDouble33& R_WC,
                   const mrpt::math::TPoint3D& t, const FrustumSides& sides,
                   double blockRadius, double maxRange)
{
	const double dx = (o.x + D / 2.0) * s - t.x, dy = (o.y + D / 2.0) * s - t.y,
	             dz = (o.z + D / 2.0) * s - t.z;
	double pc[3];
	for (int r = 0; r < 3; ++r)
		pc[r] = R_WC(0, r) * dx + R_WC(1, r) * dy + R_WC(2, r) * dz;  // R^T d
	if (pc[2] < -blockRadius || pc[2] > maxRange + blockRadius) return false;
	for (const auto& pl : sides.n)
		if (pl[0] * pc[0] + pl[1] * pc[1] + pl[2] * pc[2] < -blockRadius)
			return false;
	return true;
}

/** The terms of R^T (centre - t) per axis and index of one block's cells:
 * cell (i, j, k) has c[r] = (ax[r][i] + ay[r][j]) + az[r][k], the same
 * operations as for one cell alone. */
template <int D>
struct BlockCamTerms
{
	double ax[3][D], ay[3][D], az[3][D];

	BlockCamTerms(const VoxelKey& o, double s,
	              const mrpt::math::CMatrixDouble33& R_WC,
	              const mrpt::math::TPoint3D& t)
	{
		for (int i = 0; i < D; ++i)
		{
			const double dx = (o.x + i + 0.5) * s - t.x;
			const double dy = (o.y + i + 0.5) * s - t.y;
			const double dz = (o.z + i + 0.5) * s - t.z;
			for (int r = 0; r < 3; ++r)
			{
				ax[r][i] = R_WC(0, r) * dx;
				ay[r][i] = R_WC(1, r) * dy;
				az[r][i] = R_WC(2, r) * dz;
			}
		}
	}
	double cam(int i, int j, int k, int r) const
	{
		return ax[r][i] + ay[r][j] + az[r][k];
	}
};

/** What every block's decay reads of the frame. */
struct FrustumView
{
	const sensors::PinholeCamera& K;
	const float* depth;  ///< K.width x K.height, row-major [m]
	DepthTiles tiles;
	double cellHalfDiag;  ///< [m]
};

enum class FrustumVerdict
{
	None,   ///< no cell of the box decays
	All,    ///< every cell of the box decays
	Mixed,  ///< to be split or decided cell by cell
};

/** decay = frustum over one block: boxes decided at once where the rule
 * gives one answer for all their cells, split into octants down to 4^3
 * cells, then cell by cell. \a Miss applies one miss to a cell. */
template <int D, class Cell, class Miss>
struct BlockFrustumDecay
{
	const FrustumView& view;
	const BlockCamTerms<D> cam;
	Cell* cells;  ///< the block's D^3 cells
	uint32_t F;   ///< the frame
	const Miss& miss;

	Cell& cell(int i, int j, int k) const
	{
		return cells[size_t(i) | (size_t(j) << 3) | (size_t(k) << 6)];
	}

	/** The per-cell rule: in front of the camera, onto a measured depth d,
	 * and wholly in front of it. */
	void cellRule(int i, int j, int k) const
	{
		Cell& c = cell(i, j, k);
		if (c.stamp == F) return;
		const auto& K = view.K;
		const double z = cam.cam(i, j, k, 2);
		if (z <= 1e-6) return;
		const double u = K.fx * cam.cam(i, j, k, 0) / z + K.cx;
		const double v = K.fy * cam.cam(i, j, k, 1) / z + K.cy;
		// (far off the image, or not finite: no pixel)
		if (!(std::abs(u) < 1e15 && std::abs(v) < 1e15)) return;
		const long ui = bims::roundHalfAway(u), vi = bims::roundHalfAway(v);
		if (ui < 0 || vi < 0 || ui >= K.width || vi >= K.height) return;
		const float d = view.depth[size_t(vi) * K.width + size_t(ui)];
		// Decay only cells wholly in front of the measured depth.
		if (d > 0 && z + view.cellHalfDiag < d) miss(c);
	}

	/** The verdict for the box [i0, i0+n) x [j0, j0+n) x [k0, k0+n). */
	FrustumVerdict verdict(int i0, int j0, int k0, int n) const
	{
		const auto& K = view.K;
		const int W = K.width, H = K.height;
		const int e = n - 1;
		double zlo = INFINITY, zhi = -INFINITY;
		double ulo = INFINITY, uhi = -INFINITY, vlo = INFINITY, vhi = -INFINITY;
		for (int q = 0; q < 8; ++q)
		{
			const int i = i0 + ((q & 1) ? e : 0), j = j0 + ((q & 2) ? e : 0),
			          k = k0 + ((q & 4) ? e : 0);
			const double z = cam.cam(i, j, k, 2);
			zlo = std::min(zlo, z);
			zhi = std::max(zhi, z);
			if (z <= 1e-6 + kZMargin) return FrustumVerdict::Mixed;
			const double u = K.fx * cam.cam(i, j, k, 0) / z + K.cx;
			const double v = K.fy * cam.cam(i, j, k, 1) / z + K.cy;
			ulo = std::min(ulo, u);
			uhi = std::max(uhi, u);
			vlo = std::min(vlo, v);
			vhi = std::max(vhi, v);
		}
		// Every centre projects into [ulo, uhi] x [vlo, vhi]; its pixel
		// (rounded) into this rectangle of pixels.
		const double u0 = std::floor(ulo) - 1, u1 = std::ceil(uhi) + 1,
		             v0 = std::floor(vlo) - 1, v1 = std::ceil(vhi) + 1;
		if (u1 < 0 || v1 < 0 || u0 >= W || v0 >= H) return FrustumVerdict::None;
		const bool inside = u0 >= 0 && v0 >= 0 && u1 < W && v1 < H;
		const int pu0 = int(std::max(u0, 0.0)),
		          pu1 = int(std::min(u1, double(W - 1))),
		          pv0 = int(std::max(v0, 0.0)),
		          pv1 = int(std::min(v1, double(H - 1)));
		float dMax = 0, dMinPos = INFINITY;
		bool zero = false;
		const DepthTiles& t = view.tiles;
		for (int ty = pv0 / kTilePx; ty <= pv1 / kTilePx; ++ty)
			for (int tx = pu0 / kTilePx; tx <= pu1 / kTilePx; ++tx)
			{
				const size_t ti = size_t(ty) * t.tw + size_t(tx);
				dMax = std::max(dMax, t.max[ti]);
				dMinPos = std::min(dMinPos, t.minPos[ti]);
				zero = zero || t.zero[ti];
			}
		// No cell is in front of any depth of its rectangle.
		if (double(dMax) <= zlo + view.cellHalfDiag - kZMargin)
			return FrustumVerdict::None;
		// Every cell is in the image and in front of every depth there.
		if (inside && !zero &&
		    double(dMinPos) > zhi + view.cellHalfDiag + kZMargin)
			return FrustumVerdict::All;
		return FrustumVerdict::Mixed;
	}

	/** Decides the box of side \a n at (i0, j0, k0). */
	void decide(int i0, int j0, int k0, int n) const
	{
		const FrustumVerdict vd = verdict(i0, j0, k0, n);
		if (vd == FrustumVerdict::None) return;
		if (vd == FrustumVerdict::All)
		{
			for (int k = k0; k < k0 + n; ++k)
				for (int j = j0; j < j0 + n; ++j)
					for (int i = i0; i < i0 + n; ++i) miss(cell(i, j, k));
			return;
		}
		if (n > 4)
		{
			const int h = n / 2;
			for (int q = 0; q < 8; ++q)
				decide(i0 + ((q & 1) ? h : 0), j0 + ((q & 2) ? h : 0),
				       k0 + ((q & 4) ? h : 0), h);
			return;
		}
		for (int k = k0; k < k0 + n; ++k)
			for (int j = j0; j < j0 + n; ++j)
				for (int i = i0; i < i0 + n; ++i) cellRule(i, j, k);
	}
};
}  // namespace

void COccupancyBayesGrid::decayFrustum(const FrameCloud& f, uint32_t F)
{
	const auto& K = f.K;
	if (K.width <= 0 || f.depth.empty()) return;  // no frustum known
	const double s = params_.voxel_size;
	const auto& R = f.T_WC.getRotationMatrix();  // R_WC
	const mrpt::math::TPoint3D t = f.T_WC.translation();
	const FrustumSides sides = frustumSides(K);
	constexpr int D = Storage::kDim;
	const double blockRadius = D * s * std::sqrt(3.0) / 2;
	const FrustumView view{K, f.depth.data(),
	                       fillDepthTiles(f.depth, K.width, K.height, tileMax_,
	                                      tileMinPos_, tileZero_),
	                       s * std::sqrt(3.0) / 2};
	auto miss = [this, F](Cell& c) { applyMiss(c, F); };
	for (size_t b = 0; b < grid_.numBlocks(); ++b)
	{
		const VoxelKey o = grid_.blockOrigin(b);
		if (!blockNearView(o, D, s, R, t, sides, blockRadius,
		                   params_.max_range))
			continue;
		BlockFrustumDecay<D, Cell, decltype(miss)> decay{
		    view, BlockCamTerms<D>(o, s, R, t), grid_.block(b).cells, F, miss};
		decay.decide(0, 0, 0, D);
	}
}

}  // namespace bims::maps
