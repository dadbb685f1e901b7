// Per-pixel labels of a CObservation3DRangeScan written in one buffer.
#pragma once

#include <mrpt/math/CMatrixDynamic.h>
#include <mrpt/obs/TPixelLabelInfo.h>

#include <memory>
#include <string>

namespace bims
{
/** mrpt::obs::TPixelLabelInfo<1> (8 labels per pixel) whose serialisation
 * writes the label matrix with one buffer write: MRPT 2.5.8 writes it one
 * archive call per pixel (~3 ms of CPU per 640x480 frame). The bytes are
 * MRPT's own (test PixelLabels.BulkWriteHasMrptsBytes), so MRPT and
 * RawLogViewer read it back as a TPixelLabelInfo<1>. */
class BulkPixelLabels : public mrpt::obs::TPixelLabelInfo<1>
{
 public:
	/** One label \a name (index 0) on the pixels where \a mask (rows x
	 * cols bytes, \a stride bytes from row to row) is non-zero. */
	static std::shared_ptr<BulkPixelLabels> fromMask(const uint8_t* mask,
	                                                 int rows, int cols,
	                                                 size_t stride,
	                                                 const std::string& name);

 protected:
	void internal_writeToStream(
	    mrpt::serialization::CArchive& out) const override;
};

}  // namespace bims
