// sensor_msgs/CompressedImage as image_transport's plugins write it
// (docs/import-bag.md, "Compressed images"): compressed_image_transport's
// JPEG or PNG colour, compressed_depth_image_transport's depth (a 12-byte
// ConfigHeader, then the depth or its quantised inverse as a PNG, or as its
// size and an RVL stream). Decoded through the guarded image decoder
// (bims/io/image_file.h), RVL by our own guarded decoder: the size a
// message's image declares is checked before anything is decoded.
#pragma once

#include <bims/io/image_file.h>
#include <sensor_msgs/CompressedImage.h>

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

namespace bims::bag
{
/** What a CompressedImage's format string says. */
struct CompressedFormat
{
	/** The raw image's encoding ("rgb8", "16UC1"); empty when the format
	 * does not say (compressed_image_transport before ROS Hydro: "jpeg"). */
	std::string encoding;
	std::string codec;  ///< "jpeg", "png" or "rvl"
	/** compressed_depth_image_transport's: a ConfigHeader before the data. */
	bool depth = false;
	/** The compressed pixels are in BGR order ("compressed bgr8", or an
	 * old format that says nothing); else, for a colour encoding, RGB. */
	bool bgr = true;
};

/** Parses \a format as the plugins write it: "jpeg", "png" (old),
 * "rgb8; jpeg compressed bgr8", "mono8; png compressed ",
 * "16UC1; compressedDepth", "32FC1; compressedDepth png", "...rvl".
 * Throws std::runtime_error naming the format when it is none of these. */
CompressedFormat parseCompressedFormat(const std::string& format);

/** The colour image of a message of \a format and \a data, BGR 8-bit, \a width
 * x \a height. Throws std::runtime_error saying what is wrong: the format, an
 * encoding other than rgb8 bgr8 mono8, data that is no image of the format, a
 * declared size other than the camera's or beyond \a limits (before decoding),
 * bytes that do not decode. */
cv::Mat decodeCompressedColour(const std::string& format, const uint8_t* data,
                               size_t size, int width, int height,
                               const ImageLimits& limits);
/** The same of a ROS 1 message. */
inline cv::Mat decodeCompressedColour(const sensor_msgs::CompressedImage& m,
                                      int width, int height,
                                      const ImageLimits& limits)
{
	return decodeCompressedColour(m.format, m.data.data(), m.data.size(), width,
	                              height, limits);
}

/** The depth image of a message of \a format and \a data
 * (compressed_depth_image_transport, PNG or RVL), as the raw topic holds it:
 * 16UC1 (or mono16) millimetres as stored, or 32FC1 metres from the quantised
 * inverse depth, depthQuantA / (v - depthQuantB), 0 being NaN (no reading).
 * Throws std::runtime_error as decodeCompressedColour(), and for an RVL stream
 * that does not fill the image's pixels exactly (corrupt). */
cv::Mat decodeCompressedDepth(const std::string& format, const uint8_t* data,
                              size_t size, int width, int height,
                              const ImageLimits& limits);
/** The same of a ROS 1 message. */
inline cv::Mat decodeCompressedDepth(const sensor_msgs::CompressedImage& m,
                                     int width, int height,
                                     const ImageLimits& limits)
{
	return decodeCompressedDepth(m.format, m.data.data(), m.data.size(), width,
	                             height, limits);
}

}  // namespace bims::bag
