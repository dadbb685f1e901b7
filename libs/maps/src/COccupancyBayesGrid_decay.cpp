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
void COccupancyBayesGrid::decayFrustum(const FrameCloud& f, uint32_t F)
{
	const auto& K = f.K;
	if (K.width <= 0 || f.depth.empty()) return;  // no frustum known
	const double s = params_.voxel_size;
	const auto& R = f.T_WC.getRotationMatrix();  // R_WC
	const mrpt::math::TPoint3D t = f.T_WC.translation();
	// Side planes of the frustum in {C} (through the origin), normalised.
	double planes[4][3] = {{1, 0, (K.cx + 0.5) / K.fx},
	                       {-1, 0, (K.width - 0.5 - K.cx) / K.fx},
	                       {0, 1, (K.cy + 0.5) / K.fy},
	                       {0, -1, (K.height - 0.5 - K.cy) / K.fy}};
	for (auto& pl : planes)
	{
		const double n =
		    std::sqrt(pl[0] * pl[0] + pl[1] * pl[1] + pl[2] * pl[2]);
		for (auto& v : pl) v /= n;
	}
	const int D = Storage::kDim;
	const double blockRadius = D * s * std::sqrt(3.0) / 2;
	const double cellHalfDiag = s * std::sqrt(3.0) / 2;
	const double maxR = params_.max_range;
	auto toCam = [&](double x, double y, double z, double c[3])
	{
		const double dx = x - t.x, dy = y - t.y, dz = z - t.z;
		for (int r = 0; r < 3; ++r)
			c[r] = R(0, r) * dx + R(1, r) * dy + R(2, r) * dz;  // R^T d
	};

	// Per tile of kTilePx^2 pixels: largest depth, smallest non-zero depth
	// (+inf if none) and whether a pixel has no depth.
	constexpr int kTilePx = 8;
	const int W = K.width, H = K.height;
	const int tw = (W + kTilePx - 1) / kTilePx,
	          th = (H + kTilePx - 1) / kTilePx;
	tileMax_.assign(size_t(tw) * th, 0.f);
	tileMinPos_.assign(size_t(tw) * th, INFINITY);
	tileZero_.assign(size_t(tw) * th, 0);
	for (int v = 0; v < H; ++v)
	{
		const float* row = f.depth.data() + size_t(v) * W;
		const size_t t0 = size_t(v / kTilePx) * tw;
		for (int u = 0; u < W; ++u)
		{
			const float d = row[u];
			const size_t ti = t0 + size_t(u / kTilePx);
			tileMax_[ti] = std::max(tileMax_[ti], d);
			if (d > 0)
				tileMinPos_[ti] = std::min(tileMinPos_[ti], d);
			else
				tileZero_[ti] = 1;
		}
	}

	// Margins of the box decisions: far larger than the rounding of the
	// coordinates (~1e-14 m) and of the projections (~1e-12 px).
	constexpr double kZMargin = 1e-7;
	enum Verdict
	{
		None,
		All,
		Mixed
	};
	for (size_t b = 0; b < grid_.numBlocks(); ++b)
	{
		const VoxelKey o = grid_.blockOrigin(b);
		double pc[3];
		toCam((o.x + D / 2.0) * s, (o.y + D / 2.0) * s, (o.z + D / 2.0) * s,
		      pc);
		if (pc[2] < -blockRadius || pc[2] > maxR + blockRadius) continue;
		bool outside = false;
		for (const auto& pl : planes)
			if (pl[0] * pc[0] + pl[1] * pc[1] + pl[2] * pc[2] < -blockRadius)
				outside = true;
		if (outside) continue;
		auto& blk = grid_.block(b);
		// The terms of R^T (centre - t) per axis and index: cell (i, j, k)
		// has c[r] = (ax[r][i] + ay[r][j]) + az[r][k], as toCam() forms it.
		double ax[3][D], ay[3][D], az[3][D];
		for (int i = 0; i < D; ++i)
		{
			const double dx = (o.x + i + 0.5) * s - t.x;
			const double dy = (o.y + i + 0.5) * s - t.y;
			const double dz = (o.z + i + 0.5) * s - t.z;
			for (int r = 0; r < 3; ++r)
			{
				ax[r][i] = R(0, r) * dx;
				ay[r][i] = R(1, r) * dy;
				az[r][i] = R(2, r) * dz;
			}
		}
		auto cam = [&](int i, int j, int k, int r)
		{ return ax[r][i] + ay[r][j] + az[r][k]; };
		auto cellRule = [&](int i, int j, int k)
		{
			Cell& cell =
			    blk.cells[size_t(i) | (size_t(j) << 3) | (size_t(k) << 6)];
			if (cell.stamp == F) return;
			const double z = cam(i, j, k, 2);
			if (z <= 1e-6) return;
			const double u = K.fx * cam(i, j, k, 0) / z + K.cx;
			const double v = K.fy * cam(i, j, k, 1) / z + K.cy;
			// (far off the image, or not finite: no pixel)
			if (!(std::abs(u) < 1e15 && std::abs(v) < 1e15)) return;
			const long ui = bims::roundHalfAway(u), vi = bims::roundHalfAway(v);
			if (ui < 0 || vi < 0 || ui >= W || vi >= H) return;
			const float d = f.depth[size_t(vi) * W + size_t(ui)];
			// Decay only cells wholly in front of the measured depth.
			if (d > 0 && z + cellHalfDiag < d) applyMiss(cell, F);
		};
		// The verdict for the box [i0, i0+n) x [j0, j0+n) x [k0, k0+n).
		auto verdict = [&](int i0, int j0, int k0, int n)
		{
			const int e = n - 1;
			double zlo = INFINITY, zhi = -INFINITY;
			double ulo = INFINITY, uhi = -INFINITY, vlo = INFINITY,
			       vhi = -INFINITY;
			for (int q = 0; q < 8; ++q)
			{
				const int i = i0 + ((q & 1) ? e : 0),
				          j = j0 + ((q & 2) ? e : 0),
				          k = k0 + ((q & 4) ? e : 0);
				const double z = cam(i, j, k, 2);
				zlo = std::min(zlo, z);
				zhi = std::max(zhi, z);
				if (z <= 1e-6 + kZMargin) return Mixed;
				const double u = K.fx * cam(i, j, k, 0) / z + K.cx;
				const double v = K.fy * cam(i, j, k, 1) / z + K.cy;
				ulo = std::min(ulo, u);
				uhi = std::max(uhi, u);
				vlo = std::min(vlo, v);
				vhi = std::max(vhi, v);
			}
			// Every centre projects into [ulo, uhi] x [vlo, vhi]; its pixel
			// (rounded) into this rectangle of pixels.
			const double u0 = std::floor(ulo) - 1, u1 = std::ceil(uhi) + 1,
			             v0 = std::floor(vlo) - 1, v1 = std::ceil(vhi) + 1;
			if (u1 < 0 || v1 < 0 || u0 >= W || v0 >= H) return None;
			const bool inside = u0 >= 0 && v0 >= 0 && u1 < W && v1 < H;
			const int pu0 = int(std::max(u0, 0.0)),
			          pu1 = int(std::min(u1, double(W - 1))),
			          pv0 = int(std::max(v0, 0.0)),
			          pv1 = int(std::min(v1, double(H - 1)));
			float dMax = 0, dMinPos = INFINITY;
			bool zero = false;
			for (int ty = pv0 / kTilePx; ty <= pv1 / kTilePx; ++ty)
				for (int tx = pu0 / kTilePx; tx <= pu1 / kTilePx; ++tx)
				{
					const size_t ti = size_t(ty) * tw + size_t(tx);
					dMax = std::max(dMax, tileMax_[ti]);
					dMinPos = std::min(dMinPos, tileMinPos_[ti]);
					zero = zero || tileZero_[ti];
				}
			// No cell is in front of any depth of its rectangle.
			if (double(dMax) <= zlo + cellHalfDiag - kZMargin) return None;
			// Every cell is in the image and in front of every depth there.
			if (inside && !zero &&
			    double(dMinPos) > zhi + cellHalfDiag + kZMargin)
				return All;
			return Mixed;
		};
		auto decide = [&](auto&& self, int i0, int j0, int k0, int n) -> void
		{
			const Verdict vd = verdict(i0, j0, k0, n);
			if (vd == None) return;
			if (vd == All)
			{
				for (int k = k0; k < k0 + n; ++k)
					for (int j = j0; j < j0 + n; ++j)
						for (int i = i0; i < i0 + n; ++i)
							applyMiss(blk.cells[size_t(i) | (size_t(j) << 3) |
							                    (size_t(k) << 6)],
							          F);
				return;
			}
			if (n > 4)
			{
				const int h = n / 2;
				for (int q = 0; q < 8; ++q)
					self(self, i0 + ((q & 1) ? h : 0), j0 + ((q & 2) ? h : 0),
					     k0 + ((q & 4) ? h : 0), h);
				return;
			}
			for (int k = k0; k < k0 + n; ++k)
				for (int j = j0; j < j0 + n; ++j)
					for (int i = i0; i < i0 + n; ++i) cellRule(i, j, k);
		};
		decide(decide, 0, 0, 0, D);
	}
}

}  // namespace bims::maps
