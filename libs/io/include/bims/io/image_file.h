// The one guarded reader of image files given as input (TUM folders, Stray
// captures, labels, masks, the flow tools): the size an image declares in
// its header is checked against limits before anything is decoded, so that
// a few-kB PNG declaring 30000 x 30000 pixels is refused, not decoded into
// gigabytes. The rawlog reader checks the images inside a rawlog against
// the same limits (scan_guard).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace cv
{
class Mat;
}
namespace mrpt::config
{
class CConfigFileBase;
}

namespace bims
{
class OptionVisitor;

/** Largest image a bims input may hold by default: per side, and in
 * pixels (ImageLimits' defaults; the rawlog reader's limits). */
constexpr uint32_t kMaxImageSide = 16384;
constexpr uint64_t kMaxImagePixels = uint64_t{1} << 26;  // 67 Mpx

/** The limits an image file's declared size is checked against before it
 * is decoded: [input] of an experiment .ini (the importers read it from
 * their -c CONFIG.ini), the defaults without one. */
struct ImageLimits
{
	long max_side = kMaxImageSide;      ///< [input] image_max_side
	long max_pixels = kMaxImagePixels;  ///< [input] image_max_pixels
	/** Where the two come from, for the error of an image beyond them. */
	std::string origin = "[input] image_max_side, image_max_pixels";
	/** The largest values the two may be given (from 1). */
	static constexpr long kSideAtMost = 65535, kPixelsAtMost = 1L << 31;

	void describe(OptionVisitor& v);
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section);
};

/** What an image file's header declares. */
struct ImageHeader
{
	const char* format = "";  ///< "PNG", "JPEG", "TIFF", "BMP"
	uint32_t width = 0, height = 0;
};

/** The format and size the \a n bytes at \a p declare (PNG's IHDR, JPEG's
 * frame header, TIFF's first directory, BMP's info header); nullopt when
 * they are none of these formats or end before the size. */
std::optional<ImageHeader> imageHeader(const uint8_t* p, size_t n);

/** Whether a rows x cols image is within \a limits. */
bool imageSizeWithinLimits(uint64_t rows, uint64_t cols,
                           const ImageLimits& limits = {});

/** Why a rows x cols image (an array given to the Python module) is not
 * taken: "W x H pixels, beyond the N per side and M pixels bims reads
 * (ORIGIN)", in the words of checkImageWithinLimits(); empty when it is
 * within \a limits. */
std::string imageSizeBeyondLimits(uint64_t rows, uint64_t cols,
                                  const ImageLimits& limits);

/** Throws std::runtime_error when the size \a h declares is beyond \a limits
 * (naming the size, the format and where the limits come from) or empty:
 * decodeImage()'s check, for a size read before anything is decoded (also a
 * compressedDepth RVL image's, whose header is none of imageHeader()'s). */
void checkImageWithinLimits(const ImageHeader& h, const ImageLimits& limits);

/** Decodes the \a n bytes at \a p (an image file's contents, or a ROS
 * CompressedImage's data) as cv::imdecode(\a flags) does, but first checks
 * that they start with the header of one of the formats of imageHeader()
 * (\a format, e.g. "PNG", when given: that one) declaring a size within
 * \a limits; decodes only then. Throws std::runtime_error saying why: not
 * an image of those formats (or of \a format), a size beyond the limits
 * (with the size and the format), an empty image, or bytes that do not
 * decode. The one rule of readImageFile() and the bag importer. */
cv::Mat decodeImage(const uint8_t* p, size_t n, int flags,
                    const ImageLimits& limits = {},
                    const char* format = nullptr);

/** Reads the image file \a path as cv::imread(path, \a flags) does, but
 * first checks that it is a readable file in one of the formats of
 * imageHeader() whose declared size is within \a limits; decodes only
 * then. Throws std::runtime_error "PATH: cannot read WHAT: why" (\a what:
 * e.g. "depth image", "label"; why: no such file, a folder, empty, or
 * decodeImage()'s). */
cv::Mat readImageFile(const std::string& path, int flags,
                      const std::string& what = "image",
                      const ImageLimits& limits = {});

}  // namespace bims
