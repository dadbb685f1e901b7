#include <bims/io/pixel_labels.h>

#include <mrpt/serialization/CArchive.h>
#include <mrpt/serialization/stl_serialization.h>

#include <algorithm>
#include <vector>

namespace bims
{
std::shared_ptr<BulkPixelLabels> BulkPixelLabels::fromMask(
    const uint8_t* mask, int rows, int cols, size_t stride,
    const std::string& name)
{
	auto l = std::make_shared<BulkPixelLabels>();
	l->setSize(rows, cols);
	l->setLabelName(0, name);
	for (int v = 0; v < rows; v++)
	{
		const uint8_t* m = mask + size_t(v) * stride;
		for (int u = 0; u < cols; u++)
			l->pixelLabels(v, u) = uint8_t(m[u] != 0);
	}
	return l;
}

void BulkPixelLabels::internal_writeToStream(
    mrpt::serialization::CArchive& out) const
{
	// The layout of TPixelLabelInfo<1> (after the header writeToStream()
	// writes): rows, columns, the labels column after column, the label
	// names.
	const uint32_t nR = uint32_t(pixelLabels.rows()),
	               nC = uint32_t(pixelLabels.cols());
	out << nR << nC;
	// Column-major from the row-major matrix, in tiles (both sides stay in
	// cache).
	std::vector<uint8_t> col(size_t(nR) * nC);
	constexpr uint32_t T = 32;
	for (uint32_t r0 = 0; r0 < nR; r0 += T)
		for (uint32_t c0 = 0; c0 < nC; c0 += T)
			for (uint32_t r = r0; r < std::min(nR, r0 + T); ++r)
				for (uint32_t c = c0; c < std::min(nC, c0 + T); ++c)
					col[size_t(c) * nR + r] = pixelLabels(r, c);
	if (!col.empty()) out.WriteBuffer(col.data(), col.size());
	out << pixelLabelNames;
}

}  // namespace bims
