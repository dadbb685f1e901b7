// Per-pixel images the grids exchange with the rest: the flow labels tier 2
// takes and the moving masks the tiers give (row-major, no OpenCV).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace bims::maps
{
/** Per-pixel flow-consistency labels of one frame (input of tier 2),
 * row-major, width x height: -1 no label, 0 notDiff, 1 Diff. */
struct PixelLabels
{
	int width = 0, height = 0;
	std::vector<int8_t> label;

	PixelLabels() = default;
	PixelLabels(int w, int h, int8_t fill = -1)
	    : width(w), height(h), label(size_t(w) * size_t(h), fill)
	{
	}
	int8_t at(int u, int v) const { return label[size_t(v) * width + u]; }
	int8_t& at(int u, int v) { return label[size_t(v) * width + u]; }
};

/** A per-pixel mask (row-major uint8, 255 = moving, 0 = not). */
struct PixelMask
{
	int width = 0, height = 0;
	std::vector<uint8_t> data;
	void reset(int w, int h)
	{
		width = w;
		height = h;
		data.assign(size_t(w) * size_t(h), 0);
	}
	/** Pixels set. */
	size_t count() const
	{
		size_t n = 0;
		for (auto v : data) n += v != 0;
		return n;
	}
};

}  // namespace bims::maps
