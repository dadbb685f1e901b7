// Tier 0: the miss update for decay = frustum and decay = raycast.
#include <bims/maps/COccupancyBayesGrid.h>
#include <bims/maps/dda.h>

#include <cmath>

namespace bims::maps
{

void COccupancyBayesGrid::decayRaycast(const FrameCloud& f, uint32_t F)
{
	const double inv = 1 / params_.voxel_size;
	const auto& o = f.origin_W;
	const double ext = params_.extent;
	if (std::abs(o.x) > ext || std::abs(o.y) > ext || std::abs(o.z) > ext)
	{
		FrameStats st;
		st.outsideExtent = f.points_W.size();
		accountFrame(st);
		return;  // keys along the rays could leave the key range
	}
	const double a[3] = {o.x * inv, o.y * inv, o.z * inv};
	Storage::Accessor acc(grid_);
	size_t over = 0;
	auto visit = [&](int32_t x, int32_t y, int32_t z)
	{
		Cell* c = acc.get(x, y, z);
		if (c)
			applyMiss(*c, F);
		else
			++over;
	};
	const int dec = params_.raycast_decimation;
	if (params_.raycast_target == RayTarget::Voxels)
	{
		for (size_t i = 0; i < f.cells.size(); ++i)
		{
			if (dec > 1 && i % size_t(dec * dec) != 0) continue;
			const auto& k = f.cells[i];
			const double b[3] = {k.x + 0.5, k.y + 0.5, k.z + 0.5};
			traverseRay(a, b, visit);
		}
	}
	else
	{
		const int W = f.K.width;
		for (size_t i = 0; i < f.points_W.size(); ++i)
		{
			if (dec > 1)
			{
				if (W > 0)
				{
					const uint32_t px = f.pixel[i];
					if ((px % W) % dec != 0 || (px / W) % dec != 0) continue;
				}
				else if (i % size_t(dec) != 0)
					continue;
			}
			const auto& p = f.points_W[i];
			const double b[3] = {p.x * inv, p.y * inv, p.z * inv};
			traverseRay(a, b, visit);
		}
	}
	if (over)
	{
		FrameStats st;
		st.overBudget = over;
		accountFrame(st);
	}
}

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
		for (size_t c = 0; c < Storage::kCellsPerBlock; ++c)
		{
			Cell& cell = blk.cells[c];
			if (cell.stamp == F) continue;
			const VoxelKey k = grid_.cellKey(b, c);
			toCam((k.x + 0.5) * s, (k.y + 0.5) * s, (k.z + 0.5) * s, pc);
			if (pc[2] <= 1e-6) continue;
			const double u = K.fx * pc[0] / pc[2] + K.cx;
			const double v = K.fy * pc[1] / pc[2] + K.cy;
			const long ui = std::lround(u), vi = std::lround(v);
			if (ui < 0 || vi < 0 || ui >= K.width || vi >= K.height) continue;
			const float d = f.depth[size_t(vi) * K.width + size_t(ui)];
			// Decay only cells wholly in front of the measured depth.
			if (d > 0 && pc[2] + cellHalfDiag < d) applyMiss(cell, F);
		}
	}
}

}  // namespace bims::maps
