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

/** The size the image bytes declare must be the camera's (checked before
 * decoding: a message declaring a huge image is never decoded). */
void checkDeclaredSize(const uint8_t* p, size_t n, int width, int height)
{
	const auto h = imageHeader(p, n);
	if (h && (static_cast<int64_t>(h->width) != width ||
	          static_cast<int64_t>(h->height) != height))
		throw runtime_error(mrpt::format(
		    "its %s header declares %ux%u, the camera is %dx%d (not decoded)",
		    h->format, h->width, h->height, width, height));
}

void checkDecodedSize(const cv::Mat& img, int width, int height)
{
	if (img.cols != width || img.rows != height)
		throw runtime_error(
		    mrpt::format("it decodes to %dx%d, the camera is %dx%d", img.cols,
		                 img.rows, width, height));
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
		    "compressed bgr8'; '16UC1; compressedDepth png')");
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

cv::Mat decodeCompressedColour(const sensor_msgs::CompressedImage& m, int width,
                               int height, const ImageLimits& limits)
{
	return described(
	    "the colour image", m.format,
	    [&]
	    {
		    const CompressedFormat f = parseCompressedFormat(m.format);
		    if (f.depth)
			    throw runtime_error(
			        "a compressedDepth image where colour belongs");
		    static const std::set<std::string> encodings = {"bgr8", "mono8",
		                                                    "rgb8"};
		    if (!f.encoding.empty() && !encodings.count(f.encoding))
			    throw runtime_error("encoding '" + f.encoding +
			                        "' is not supported (bgr8, mono8, rgb8)");
		    const uint8_t* p = m.data.data();
		    const size_t n = m.data.size();
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

cv::Mat decodeCompressedDepth(const sensor_msgs::CompressedImage& m, int width,
                              int height, const ImageLimits& limits)
{
	return described(
	    "the depth image", m.format,
	    [&]
	    {
		    const CompressedFormat f = parseCompressedFormat(m.format);
		    if (!f.depth)
			    throw runtime_error(
			        "not compressed_depth_image_transport's compressedDepth "
			        "(e.g. '16UC1; compressedDepth png'): a depth image "
			        "compressed otherwise is not read");
		    if (f.codec == "rvl")
			    throw runtime_error(
			        "RVL is not read: record the depth with the "
			        "compressedDepth plugin's png format, or the raw topic");
		    const bool metres = f.encoding == "32FC1";
		    if (!metres && f.encoding != "16UC1" && f.encoding != "mono16")
			    throw runtime_error("encoding '" + f.encoding +
			                        "' is not supported (16UC1, 32FC1, "
			                        "mono16)");
		    // the plugin's ConfigHeader: int32 format (INV_DEPTH = 0), float
		    // depthQuantA, float depthQuantB, in the writer's byte order
		    constexpr size_t kHeader = 12;
		    if (m.data.size() <= kHeader)
			    throw runtime_error(mrpt::format(
			        "%zu bytes of data: %s", m.data.size(),
			        m.data.size() < kHeader
			            ? "cut inside its 12-byte compressedDepth header"
			            : "its 12-byte compressedDepth header, no image"));
		    int32_t kind = 0;
		    float quant[2] = {};
		    std::memcpy(&kind, m.data.data(), 4);
		    std::memcpy(quant, m.data.data() + 4, 8);
		    if (kind != 0)
			    throw runtime_error(mrpt::format(
			        "its compressedDepth header's format is %d, not INV_DEPTH "
			        "(0): corrupt",
			        kind));
		    if (metres && !(std::isfinite(quant[0]) &&
		                    std::isfinite(quant[1]) && quant[0] != 0))
			    throw runtime_error(mrpt::format(
			        "its compressedDepth header's depth quantisation (%g, %g) "
			        "is no inverse depth's: corrupt",
			        quant[0], quant[1]));
		    const uint8_t* p = m.data.data() + kHeader;
		    const size_t n = m.data.size() - kHeader;
		    checkDeclaredSize(p, n, width, height);
		    const cv::Mat img =
		        decodeImage(p, n, cv::IMREAD_UNCHANGED, limits, "PNG");
		    if (img.type() != CV_16UC1)
			    throw runtime_error(mrpt::format(
			        "its PNG decodes to %d channel(s) of %d bytes, not 16-bit "
			        "grey",
			        img.channels(), static_cast<int>(img.elemSize1())));
		    checkDecodedSize(img, width, height);
		    if (!metres) return img;
		    // compressed_depth_image_transport's decoding of the inverse
		    // depth, in float as there: 0 is no reading
		    cv::Mat depth(img.size(), CV_32FC1);
		    for (int v = 0; v < img.rows; v++)
		    {
			    const auto* in = img.ptr<uint16_t>(v);
			    auto* out = depth.ptr<float>(v);
			    for (int u = 0; u < img.cols; u++)
				    out[u] = in[u] ? quant[0] /
				                         (static_cast<float>(in[u]) - quant[1])
				                   : std::numeric_limits<float>::quiet_NaN();
		    }
		    return depth;
	    });
}

}  // namespace bims::bag
