// Checks the sizes a serialized observation declares, before MRPT allocates
// them.
//
// MRPT 2.5.8's readers trust the stored sizes: a corrupt depth-image height
// of 0x7fffffff makes CObservation3DRangeScan allocate 1.3 TB, which fails
// without an exception, and the next memset crashes the process; a string
// length of 0xffffffff (an IMU's sensor label) allocates 4 GB. The rawlog
// reader walks each top-level 3D scan's and IMU observation's bytes first
// and refuses declared sizes no real sensor produces.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>

namespace bims
{
/** Largest image side and pixel count a rawlog's scan may declare (a 16384 x
 * 4096 image; real RGB-D sensors give at most a few megapixels). */
constexpr uint32_t kMaxImageSide = 16384;
constexpr uint64_t kMaxImagePixels = uint64_t{1} << 26;
/** Largest string or byte block (labels, file names, a JPEG image) an
 * observation may declare. */
constexpr uint64_t kMaxStringBytes = uint64_t{1} << 26;

/** The next bytes of the stream without consuming them: at least n unless
 * the file ends first. */
using PeekFn = std::function<std::pair<const uint8_t*, size_t>(size_t n)>;

/** For a top-level object of a class MRPT does not know, that problem;
 * for a top-level mrpt::obs::CObservation3DRangeScan of serialization
 * version 9 or 10 or mrpt::obs::CObservationIMU of version 4 (what MRPT 2.x
 * writes), the problem with its declared point count, the size of one of
 * its images (depth, intensity, confidence, pixel labels, extra layers) or
 * the length of one of its strings ("" when they are sane, when the object
 * is of another class or version or holds a layout the walk does not know,
 * or when the file ends first: MRPT's reader then reports the
 * truncation), or, with *truncated = true, that a block it declares (points,
 * an image, a string) runs past the end of the file. */
std::string checkSerializedSizes(const PeekFn& peek, bool* truncated = nullptr);

}  // namespace bims
