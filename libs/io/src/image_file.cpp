#include <bims/common/input_file.h>
#include <bims/common/options.h>
#include <bims/io/image_file.h>

#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <vector>

namespace bims
{
namespace
{
uint32_t be16(const uint8_t* p)
{
	return uint32_t(p[0]) << 8 | p[1];
}
uint32_t be32(const uint8_t* p)
{
	return be16(p) << 16 | be16(p + 2);
}
uint32_t le16(const uint8_t* p)
{
	return uint32_t(p[1]) << 8 | p[0];
}
uint32_t le32(const uint8_t* p)
{
	return le16(p + 2) << 16 | le16(p);
}

std::optional<ImageHeader> pngHeader(const uint8_t* p, size_t n)
{
	static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
	if (n < 24 || !std::equal(sig, sig + 8, p)) return std::nullopt;
	if (!std::equal(p + 12, p + 16, "IHDR")) return std::nullopt;
	return ImageHeader{"PNG", be32(p + 16), be32(p + 20)};
}

/** The frame header (SOF marker) of a JPEG: height, width. */
std::optional<ImageHeader> jpegHeader(const uint8_t* p, size_t n)
{
	if (n < 2 || p[0] != 0xff || p[1] != 0xd8) return std::nullopt;  // SOI
	size_t i = 2;
	while (i + 4 <= n && p[i] == 0xff)
	{
		const uint8_t marker = p[i + 1];
		if (marker == 0xff)  // fill byte
		{
			i++;
			continue;
		}
		// SOF0-SOF15 but DHT (c4), JPG (c8), DAC (cc): height, width
		if (marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 &&
		    marker != 0xc8 && marker != 0xcc)
		{
			if (i + 9 > n) return std::nullopt;
			return ImageHeader{"JPEG", be16(p + i + 7), be16(p + i + 5)};
		}
		if (marker == 0xda || marker == 0xd9) return std::nullopt;  // SOS, EOI
		i += 2 + be16(p + i + 2);  // the segment
	}
	return std::nullopt;
}

/** ImageWidth (256) and ImageLength (257) of a TIFF's first directory. */
std::optional<ImageHeader> tiffHeader(const uint8_t* p, size_t n)
{
	if (n < 8) return std::nullopt;
	const bool le = p[0] == 'I' && p[1] == 'I';
	const bool be = p[0] == 'M' && p[1] == 'M';
	if (!le && !be) return std::nullopt;
	const auto u16 = [&](size_t at)
	{ return le ? le16(p + at) : be16(p + at); };
	const auto u32 = [&](size_t at)
	{ return le ? le32(p + at) : be32(p + at); };
	if (u16(2) != 42) return std::nullopt;  // (BigTIFF is 43: not read)
	const size_t ifd = u32(4);
	if (ifd > n || n - ifd < 2) return std::nullopt;
	const size_t count = u16(ifd);
	std::optional<uint32_t> w, h;
	for (size_t k = 0; k < count; ++k)
	{
		const size_t e = ifd + 2 + 12 * k;
		if (e + 12 > n) return std::nullopt;
		const uint32_t tag = u16(e), type = u16(e + 2);
		if (tag != 256 && tag != 257) continue;
		uint32_t v = 0;
		if (type == 3)  // SHORT: in the first two bytes of the field
			v = u16(e + 8);
		else if (type == 4)  // LONG
			v = u32(e + 8);
		else
			return std::nullopt;
		(tag == 256 ? w : h) = v;
	}
	if (!w || !h) return std::nullopt;
	return ImageHeader{"TIFF", *w, *h};
}

std::optional<ImageHeader> bmpHeader(const uint8_t* p, size_t n)
{
	if (n < 26 || p[0] != 'B' || p[1] != 'M') return std::nullopt;
	const uint32_t dib = le32(p + 14);
	if (dib == 12)  // BITMAPCOREHEADER: 16-bit sizes
		return ImageHeader{"BMP", le16(p + 18), le16(p + 20)};
	if (dib < 40) return std::nullopt;
	const auto w = static_cast<int32_t>(le32(p + 18));
	const auto h = static_cast<int32_t>(le32(p + 22));  // < 0: top-down
	const auto mag = [](int32_t v)
	{ return static_cast<uint32_t>(v < 0 ? -int64_t(v) : int64_t(v)); };
	return ImageHeader{"BMP", mag(w), mag(h)};
}
}  // namespace

std::optional<ImageHeader> imageHeader(const uint8_t* p, size_t n)
{
	for (auto f : {pngHeader, jpegHeader, tiffHeader, bmpHeader})
		if (auto h = f(p, n)) return h;
	return std::nullopt;
}

void ImageLimits::describe(OptionVisitor& v)
{
	v.integer("image_max_side", max_side, 1, kSideAtMost,
	          "an input image file (TUM folder, Stray capture, labels) or a "
	          "bag's compressed image declaring more pixels per side is "
	          "refused before decoding");
	v.integer("image_max_pixels", max_pixels, 1, kPixelsAtMost,
	          "an input image file or a bag's compressed image declaring more "
	          "pixels (width x height) is refused before decoding");
}

void ImageLimits::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                     const std::string& section)
{
	readOptions(*this, cfg, section);
}

bool imageSizeWithinLimits(uint64_t rows, uint64_t cols,
                           const ImageLimits& limits)
{
	const auto side = static_cast<uint64_t>(limits.max_side);
	return rows <= side && cols <= side &&
	       rows * cols <= static_cast<uint64_t>(limits.max_pixels);
}

namespace
{
/** "beyond the N per side and M pixels bims reads (ORIGIN": the refusal of
 * every image's size, without its closing parenthesis. */
std::string beyondLimits(const ImageLimits& limits)
{
	return "beyond the " + std::to_string(limits.max_side) + " per side and " +
	       std::to_string(limits.max_pixels) + " pixels bims reads (" +
	       limits.origin;
}
}  // namespace

std::string imageSizeBeyondLimits(uint64_t rows, uint64_t cols,
                                  const ImageLimits& limits)
{
	if (imageSizeWithinLimits(rows, cols, limits)) return {};
	return std::to_string(cols) + " x " + std::to_string(rows) + " pixels, " +
	       beyondLimits(limits) + ")";
}

void checkImageWithinLimits(const ImageHeader& h, const ImageLimits& limits)
{
	using std::runtime_error;
	if (!imageSizeWithinLimits(h.height, h.width, limits))
		throw runtime_error("declares " + std::to_string(h.width) + " x " +
		                    std::to_string(h.height) + " pixels in its " +
		                    h.format + " header, " + beyondLimits(limits) +
		                    "; not decoded)");
	if (h.width == 0 || h.height == 0)
		throw runtime_error(std::string("declares an empty image in its ") +
		                    h.format + " header");
}

cv::Mat decodeImage(const uint8_t* p, size_t n, int flags,
                    const ImageLimits& limits, const char* format)
{
	using std::runtime_error;
	const auto h = imageHeader(p, n);
	if (!h)
		throw runtime_error(
		    format
		        ? std::string("not a ") + format + " image (no header of one)"
		        : "not a PNG, JPEG, TIFF or BMP image (no header of one)");
	if (format && std::string(h->format) != format)
		throw runtime_error(std::string("a ") + h->format + " image, not " +
		                    format);
	checkImageWithinLimits(*h, limits);
	cv::Mat img;
	try
	{
		// (imdecode does not write to its input)
		img = cv::imdecode(
		    cv::Mat(1, static_cast<int>(n), CV_8UC1, const_cast<uint8_t*>(p)),
		    flags);
	}
	catch (const cv::Exception&)
	{
	}
	if (img.empty())
		throw runtime_error(std::string("its bytes do not decode as ") +
		                    h->format + " (damaged or truncated)");
	return img;
}

cv::Mat readImageFile(const std::string& path, int flags,
                      const std::string& what, const ImageLimits& limits)
{
	const auto fail = [&](const std::string& why)
	{ return std::runtime_error(path + ": cannot read " + what + ": " + why); };
	// a regular file only (a FIFO would block, /dev/zero never end): the
	// error names the file and what it is
	InputFile f(path, what);
	// a compressed image is never larger than its pixels (at 8 bytes each)
	const uint64_t size = f.size();
	if (size > static_cast<uint64_t>(limits.max_pixels) * 8)
		throw fail("larger than any image bims reads (" + std::to_string(size) +
		           " bytes)");
	std::vector<uint8_t> bytes(static_cast<size_t>(size));
	size_t got = 0;
	while (got < bytes.size())
	{
		const size_t n = f.read(bytes.data() + got, bytes.size() - got);
		if (n == 0) throw fail("the file ends early");
		got += n;
	}
	if (bytes.empty()) throw fail("the file is empty");
	try
	{
		return decodeImage(bytes.data(), bytes.size(), flags, limits);
	}
	catch (const std::runtime_error& e)
	{
		throw fail(e.what());
	}
}

}  // namespace bims
