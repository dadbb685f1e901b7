#include <bims/bag/compressed_image.h>

#include <mrpt/core/format.h>
#include <sensor_msgs/image_encodings.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace bims::bag
{
namespace
{
using std::runtime_error;

std::string trimmed(const std::string& s)
{
	const size_t a = s.find_first_not_of(" \t");
	if (a == std::string::npos) return "";
	return s.substr(a, s.find_last_not_of(" \t") - a + 1);
}

/** The size an image declares (\a h, read before decoding) must be the
 * camera's: a message declaring a huge image is never decoded. */
void checkDeclaredSize(const ImageHeader& h, int width, int height)
{
	if (static_cast<int64_t>(h.width) != width ||
	    static_cast<int64_t>(h.height) != height)
		throw runtime_error(mrpt::format(
		    "its %s header declares %ux%u, the camera is %dx%d (not decoded)",
		    h.format, h.width, h.height, width, height));
}

void checkDeclaredSize(const uint8_t* p, size_t n, int width, int height)
{
	if (const auto h = imageHeader(p, n)) checkDeclaredSize(*h, width, height);
}

void checkDecodedSize(const cv::Mat& img, int width, int height)
{
	if (img.cols != width || img.rows != height)
		throw runtime_error(
		    mrpt::format("it decodes to %dx%d, the camera is %dx%d", img.cols,
		                 img.rows, width, height));
}

/** compressed_depth_image_transport's ConfigHeader, before the image: int32
 * format (INV_DEPTH = 0), float depthQuantA, float depthQuantB, in the
 * writer's byte order. */
constexpr size_t kDepthHeader = 12;
struct DepthHeader
{
	float quantA = 0, quantB = 0;
};

/** The ConfigHeader of \a data, checked; an image must follow it. */
DepthHeader depthHeader(const uint8_t* data, size_t size, bool metres)
{
	if (size <= kDepthHeader)
		throw runtime_error(
		    mrpt::format("%zu bytes of data: %s", size,
		                 size < kDepthHeader
		                     ? "cut inside its 12-byte compressedDepth header"
		                     : "its 12-byte compressedDepth header, no image"));
	int32_t kind = 0;
	DepthHeader h;
	std::memcpy(&kind, data, 4);
	std::memcpy(&h.quantA, data + 4, 4);
	std::memcpy(&h.quantB, data + 8, 4);
	if (kind != 0)
		throw runtime_error(mrpt::format(
		    "its compressedDepth header's format is %d, not INV_DEPTH (0): "
		    "corrupt",
		    kind));
	if (metres &&
	    !(std::isfinite(h.quantA) && std::isfinite(h.quantB) && h.quantA != 0))
		throw runtime_error(mrpt::format(
		    "its compressedDepth header's depth quantisation (%g, %g) is no "
		    "inverse depth's: corrupt",
		    h.quantA, h.quantB));
	return h;
}

/** The 16-bit image of the PNG codec. */
cv::Mat pngDepth(const uint8_t* p, size_t n, int width, int height,
                 const ImageLimits& limits)
{
	checkDeclaredSize(p, n, width, height);
	const cv::Mat img = decodeImage(p, n, cv::IMREAD_UNCHANGED, limits, "PNG");
	if (img.type() != CV_16UC1)
		throw runtime_error(mrpt::format(
		    "its PNG decodes to %d channel(s) of %d bytes, not 16-bit grey",
		    img.channels(), static_cast<int>(img.elemSize1())));
	checkDecodedSize(img, width, height);
	return img;
}

/** Andrew D. Wilson's RVL ("Fast Lossless Depth Image Compression", ISS
 * 2017) as compressed_depth_image_transport writes it: pairs of runs, the
 * count of zeros then of readings, each reading as its difference from the
 * reading before (across runs and rows; the first from 0) mapped to a
 * natural number (d >= 0: 2d, else -2d - 1). Every number is written 3 bits
 * a nibble, the lowest first, the nibble's high bit set when more follow;
 * the nibbles fill 32-bit words (in the writer's byte order) from the high
 * end, the last word padded with zero nibbles. Nothing a stream says is
 * trusted: it is read within its bytes, into the image's pixels only, and
 * must fill them exactly. */
class RvlDecoder
{
 public:
	RvlDecoder(const uint8_t* p, size_t n) : p_(p), end_(p + n), n_(n) {}

	void decode(uint16_t* out, size_t pixels)
	{
		total_ = pixels;
		int64_t previous = 0;
		while (at_ < total_)
		{
			at_ += run("zeros");  // the pixels are zeros already
			for (size_t k = run("readings"); k > 0; k--)
			{
				const uint64_t u = number();
				const int64_t d = (u & 1) ? -static_cast<int64_t>(u >> 1) - 1
				                          : static_cast<int64_t>(u >> 1);
				if (previous + d < 1 || previous + d > 65535)
					throw corrupt(mrpt::format(
					    "gives a reading of %lld (a difference of %lld from "
					    "%lld) %s",
					    static_cast<long long>(previous + d),
					    static_cast<long long>(d),
					    static_cast<long long>(previous), where().c_str()));
				previous += d;
				out[at_++] = static_cast<uint16_t>(previous);
			}
		}
		// the writer ends on the pair that fills the image (a last run of
		// zeros has a count of readings, 0, after it), then pads its word
		if (word_ != 0 || p_ != end_)
			throw corrupt("goes on after the image's last pixel");
	}

 private:
	/** A run's length, within the pixels left. */
	size_t run(const char* what)
	{
		const uint64_t r = number();
		if (r > total_ - at_)
			throw corrupt(mrpt::format(
			    "has a run of %llu %s where %zu pixels are left, %s",
			    static_cast<unsigned long long>(r), what, total_ - at_,
			    where().c_str()));
		return static_cast<size_t>(r);
	}

	/** The next number; its nibbles within 33 bits (a run or a difference
	 * of a bounded image is far shorter). */
	uint64_t number()
	{
		uint64_t v = 0;
		for (int shift = 0; shift <= 30; shift += 3)
		{
			const uint32_t nibble = next();
			v |= uint64_t{nibble & 7} << shift;
			if (!(nibble & 8)) return v;
		}
		throw corrupt("has a number of more than 11 nibbles " + where());
	}

	uint32_t next()
	{
		if (left_ == 0)
		{
			if (end_ - p_ < 4) throw corrupt("ends early, " + where());
			std::memcpy(&word_, p_, 4);
			p_ += 4;
			left_ = 8;
		}
		const uint32_t nibble = word_ >> 28;
		word_ <<= 4;  // what is left of the word: its padding when 0
		left_--;
		return nibble;
	}

	std::string where() const
	{
		return mrpt::format("at pixel %zu of %zu", at_, total_);
	}

	runtime_error corrupt(const std::string& what) const
	{
		return runtime_error(mrpt::format(
		    "its RVL stream (%zu bytes) %s: corrupt", n_, what.c_str()));
	}

	const uint8_t* p_;
	const uint8_t* const end_;
	const size_t n_;
	size_t at_ = 0, total_ = 0;
	uint32_t word_ = 0;
	int left_ = 0;  ///< nibbles of word_ not read
};

/** The 16-bit image of the RVL codec: uint32 cols and rows (the writer's
 * byte order), then the RVL stream. The size must be the camera's, and
 * within \a limits, before the pixels are allocated. */
cv::Mat rvlDepth(const uint8_t* p, size_t n, int width, int height,
                 const ImageLimits& limits)
{
	if (n < 8)
		throw runtime_error(mrpt::format(
		    "%zu bytes of data: cut inside the RVL image's size (uint32 cols, "
		    "rows) after its 12-byte compressedDepth header",
		    kDepthHeader + n));
	ImageHeader h{"RVL"};
	std::memcpy(&h.width, p, 4);
	std::memcpy(&h.height, p + 4, 4);
	checkDeclaredSize(h, width, height);
	checkImageWithinLimits(h, limits);
	cv::Mat img = cv::Mat::zeros(height, width, CV_16UC1);
	RvlDecoder(p + 8, n - 8).decode(img.ptr<uint16_t>(), img.total());
	return img;
}

/** compressed_depth_image_transport's decoding of the quantised inverse
 * depth \a v, in float as there: depthQuantA / (v - depthQuantB) metres, 0
 * being no reading (NaN). */
cv::Mat metresOfInverseDepth(const cv::Mat& v, const DepthHeader& h)
{
	cv::Mat depth(v.size(), CV_32FC1);
	for (int r = 0; r < v.rows; r++)
	{
		const auto* in = v.ptr<uint16_t>(r);
		auto* out = depth.ptr<float>(r);
		for (int c = 0; c < v.cols; c++)
			out[c] = in[c] ? h.quantA / (static_cast<float>(in[c]) - h.quantB)
			               : std::numeric_limits<float>::quiet_NaN();
	}
	return depth;
}

/** Runs \a decode, its errors prefixed with what and which format. */
template <typename F>
cv::Mat described(const char* what, const std::string& format, F decode)
{
	try
	{
		return decode();
	}
	catch (const std::exception& e)
	{
		throw runtime_error(std::string(what) + " (CompressedImage, format '" +
		                    format + "'): " + e.what());
	}
}
}  // namespace

CompressedFormat parseCompressedFormat(const std::string& format)
{
	const auto bad = [&]
	{
		return runtime_error(
		    "format '" + format +
		    "' is none image_transport writes (jpeg, png; 'rgb8; jpeg "
		    "compressed bgr8'; '16UC1; compressedDepth png' or rvl)");
	};
	CompressedFormat f;
	const size_t semi = format.find(';');
	std::istringstream words(
	    semi == std::string::npos ? format : format.substr(semi + 1));
	std::string w1, w2, w3, more;
	words >> w1 >> w2 >> w3 >> more;
	if (semi == std::string::npos)
	{
		// compressed_image_transport before ROS Hydro: the codec alone
		if ((w1 != "jpeg" && w1 != "png") || !w2.empty()) throw bad();
		f.codec = w1;
		return f;
	}
	f.encoding = trimmed(format.substr(0, semi));
	if (f.encoding.empty()) throw bad();
	if (w1 == "compressedDepth")
	{
		// "compressedDepth" alone: the plugin's versions before RVL (PNG)
		f.depth = true;
		f.codec = w2.empty() ? "png" : w2;
		if ((f.codec != "png" && f.codec != "rvl") || !w3.empty()) throw bad();
		return f;
	}
	if ((w1 != "jpeg" && w1 != "png") || w2 != "compressed" || !more.empty())
		throw bad();
	f.codec = w1;
	f.bgr = w3.rfind("bgr", 0) == 0;
	return f;
}

cv::Mat decodeCompressedColour(const std::string& format, const uint8_t* data,
                               size_t size, int width, int height,
                               const ImageLimits& limits)
{
	return described(
	    "the colour image", format,
	    [&]
	    {
		    const CompressedFormat f = parseCompressedFormat(format);
		    if (f.depth)
			    throw runtime_error(
			        "a compressedDepth image where colour belongs");
		    static const std::set<std::string> encodings = {"bgr8", "mono8",
		                                                    "rgb8"};
		    if (!f.encoding.empty() && !encodings.count(f.encoding))
			    throw runtime_error("encoding '" + f.encoding +
			                        "' is not supported (bgr8, mono8, rgb8)");
		    const uint8_t* p = data;
		    const size_t n = size;
		    checkDeclaredSize(p, n, width, height);
		    const cv::Mat img = decodeImage(p, n, cv::IMREAD_UNCHANGED, limits,
		                                    f.codec == "png" ? "PNG" : "JPEG");
		    if (img.depth() != CV_8U ||
		        (img.channels() != 1 && img.channels() != 3))
			    throw runtime_error(mrpt::format(
			        "it decodes to %d channel(s) of %d bytes: not 8-bit grey "
			        "or colour",
			        img.channels(), static_cast<int>(img.elemSize1())));
		    checkDecodedSize(img, width, height);
		    cv::Mat bgr;
		    if (img.channels() == 1)
			    cv::cvtColor(img, bgr, cv::COLOR_GRAY2BGR);
		    else if (!f.bgr &&
		             sensor_msgs::image_encodings::isColor(f.encoding))
			    cv::cvtColor(img, bgr, cv::COLOR_RGB2BGR);
		    else
			    bgr = img;
		    return bgr;
	    });
}

cv::Mat decodeCompressedDepth(const std::string& format, const uint8_t* data,
                              size_t size, int width, int height,
                              const ImageLimits& limits)
{
	return described(
	    "the depth image", format,
	    [&]
	    {
		    const CompressedFormat f = parseCompressedFormat(format);
		    if (!f.depth)
			    throw runtime_error(
			        "not compressed_depth_image_transport's compressedDepth "
			        "(e.g. '16UC1; compressedDepth png'): a depth image "
			        "compressed otherwise is not read");
		    const bool metres = f.encoding == "32FC1";
		    if (!metres && f.encoding != "16UC1" && f.encoding != "mono16")
			    throw runtime_error("encoding '" + f.encoding +
			                        "' is not supported (16UC1, 32FC1, "
			                        "mono16)");
		    const DepthHeader h = depthHeader(data, size, metres);
		    const uint8_t* p = data + kDepthHeader;
		    const size_t n = size - kDepthHeader;
		    const cv::Mat img = f.codec == "rvl"
		                            ? rvlDepth(p, n, width, height, limits)
		                            : pngDepth(p, n, width, height, limits);
		    return metres ? metresOfInverseDepth(img, h) : img;
	    });
}

}  // namespace bims::bag
