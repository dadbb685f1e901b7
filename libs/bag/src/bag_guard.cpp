#include "bag_guard.h"

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

namespace bims::bag
{
using std::runtime_error;

namespace
{
/** Reads a serialized ROS message's fields in order, each length checked
 * against the bytes left. */
class Cursor
{
 public:
	Cursor(const uint8_t* p, size_t n) : p_(p), n_(n) {}
	void skip(uint64_t k, const char* what)
	{
		if (k > n_ - i_)
			throw runtime_error("its " + std::string(what) + " declares " +
			                    std::to_string(k) + " bytes, the message has " +
			                    std::to_string(n_ - i_) + " left: corrupt");
		i_ += static_cast<size_t>(k);
	}
	uint32_t u32(const char* what)
	{
		if (n_ - i_ < 4)
			throw runtime_error("the message ends inside its " +
			                    std::string(what) + ": corrupt");
		uint32_t v = 0;
		std::memcpy(&v, p_ + i_, 4);
		i_ += 4;
		return v;
	}
	uint8_t u8(const char* what)
	{
		if (n_ == i_)
			throw runtime_error("the message ends before its " +
			                    std::string(what) + ": corrupt");
		return p_[i_++];
	}
	/** \a k bytes, skipped: where they are. */
	const uint8_t* take(uint64_t k, const char* what)
	{
		const uint8_t* at = p_ + i_;
		skip(k, what);
		return at;
	}
	/** A string or array of \a elem-byte elements. */
	void array(uint64_t elem, const char* what)
	{
		skip(u32(what) * elem, what);
	}
	std::string string(const char* what)
	{
		const uint32_t k = u32(what);
		return std::string(reinterpret_cast<const char*>(take(k, what)), k);
	}
	/** Where the bytes not read yet are, and how many. */
	const uint8_t* rest(size_t& k) const
	{
		k = n_ - i_;
		return p_ + i_;
	}
	void header()
	{
		skip(12, "header");  // seq, stamp
		array(1, "header's frame_id");
	}

 private:
	const uint8_t* p_;
	size_t n_, i_ = 0;
};
}  // namespace

ImageView imageView(const uint8_t* bytes, size_t n)
{
	Cursor c(bytes, n);
	c.header();
	ImageView v;
	v.height = c.u32("height");
	v.width = c.u32("width");
	v.encoding = c.string("encoding");
	v.bigEndian = c.u8("is_bigendian") != 0;
	v.step = c.u32("step");
	v.size = c.u32("data");
	v.data = c.take(v.size, "data");
	v.tail = c.rest(v.tailSize);
	return v;
}

CompressedView compressedView(const uint8_t* bytes, size_t n)
{
	Cursor c(bytes, n);
	c.header();
	CompressedView v;
	uint32_t sec = 0, nsec = 0;
	std::memcpy(&sec, bytes + 4, 4);
	std::memcpy(&nsec, bytes + 8, 4);
	v.t = stampSeconds(sec, nsec);
	v.format = c.string("format");
	v.size = c.u32("data");
	v.data = c.take(v.size, "data");
	return v;
}

void checkMessageArrays(const uint8_t* bytes, size_t n, ArrayMessage kind)
{
	Cursor c(bytes, n);
	c.header();
	switch (kind)
	{
		case ArrayMessage::Image:
			c.skip(8, "height and width");
			c.array(1, "encoding");
			c.skip(5, "is_bigendian and step");
			c.array(1, "data");
			break;
		case ArrayMessage::CompressedImage:
			c.array(1, "format");
			c.array(1, "data");
			break;
		case ArrayMessage::CameraInfo:
			c.skip(8, "height and width");
			c.array(1, "distortion_model");
			c.array(8, "D");
			break;
		case ArrayMessage::HeaderOnly:
			break;
	}
}

}  // namespace bims::bag
