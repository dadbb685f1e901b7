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

#include <bims/io/image_file.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>

namespace bims
{
// The largest image side and pixel count a rawlog's scan may declare are
// those of every image input (bims/io/image_file.h: a 16384 x 4096
// image; real RGB-D sensors give at most a few megapixels).
/** Largest string or byte block (labels, file names, a JPEG image) an
 * observation may declare. */
constexpr uint64_t kMaxStringBytes = uint64_t{1} << 26;

/** The next bytes of the stream without consuming them: at least n unless
 * the file ends first. */
using PeekFn = std::function<std::pair<const uint8_t*, size_t>(size_t n)>;

/** For a top-level object of a class MRPT does not know, that problem;
 * for a top-level mrpt::obs::CObservation3DRangeScan (every serialization
 * version MRPT 2.5.8 reads, 0 to 10: MRPT 1.x's layouts too) or
 * mrpt::obs::CObservationIMU (0 to 4), walked with the inner objects it
 * holds (poses, images, camera models, matrices of each version MRPT
 * reads), the problem with its declared point count, the size of one of its
 * images (depth, intensity, confidence, pixel labels, extra layers) or
 * matrices, the length of one of its strings or vectors, a flag that is no
 * bool, or a layout MRPT's reader would fail on only after allocating ("" when
 * they are sane, when the object is of another class or of a version MRPT
 * refuses, or when the file ends first: MRPT's reader then reports the
 * truncation), or, with *truncated = true, that a block it declares (points,
 * an image, a string) runs past the end of the file. */
std::string checkSerializedSizes(const PeekFn& peek, bool* truncated = nullptr);

}  // namespace bims
