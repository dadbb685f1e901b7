#include "scan_guard.h"

#include <cstring>

namespace bims
{
namespace
{
/** Reads MRPT's archive layout from peeked bytes; every read is bounds
 * checked and sets ok = false past the available bytes. */
class Cursor
{
 public:
	explicit Cursor(const PeekFn& peek) : peek_(peek) {}
	bool ok() const { return ok_; }
	size_t offset() const { return at_; }

	template <typename T>
	T read()
	{
		T v{};
		if (need(sizeof(T))) std::memcpy(&v, data_ + at_, sizeof(T));
		at_ += sizeof(T);
		return v;
	}
	void skip(uint64_t n)
	{
		if (need(n)) at_ += n;
	}
	/** An object header: class name (length byte with the high bit set,
	 * then the name) and the version byte; "" if not in that form. */
	std::string header(uint8_t& version)
	{
		const auto len = read<uint8_t>();
		if (!ok_ || !(len & 0x80)) return {};
		const size_t n = len & 0x7f;
		if (!need(n)) return {};
		std::string name(reinterpret_cast<const char*>(data_ + at_), n);
		at_ += n;
		version = read<uint8_t>();
		return ok_ ? name : std::string{};
	}

 private:
	bool need(uint64_t n)
	{
		if (!ok_) return false;
		if (at_ + n > size_)
		{
			const auto got = peek_(at_ + n);
			data_ = got.first;
			size_ = got.second;
			if (at_ + n > size_) ok_ = false;
		}
		return ok_;
	}

	const PeekFn& peek_;
	const uint8_t* data_ = nullptr;
	size_t size_ = 0;
	size_t at_ = 0;
	bool ok_ = true;
};

std::string tooLarge(const std::string& what, uint64_t rows, uint64_t cols)
{
	return what + " is " + std::to_string(rows) + " x " + std::to_string(cols) +
	       " (rows x columns), beyond the " + std::to_string(kMaxImageSide) +
	       " per side and " + std::to_string(kMaxImagePixels) +
	       " pixels a rawlog may hold";
}
}  // namespace

std::string checkSerializedScanSizes(const PeekFn& peek)
{
	Cursor c(peek);
	uint8_t version = 0;
	if (c.header(version) != "mrpt::obs::CObservation3DRangeScan") return {};
	if (version != 9 && version != 10) return {};
	c.skip(sizeof(float));  // maxRange
	uint8_t poseVersion = 0;
	if (c.header(poseVersion) != "mrpt::poses::CPose3D" || poseVersion != 3)
		return {};  // a layout this check does not know: MRPT decides
	c.skip(12 * sizeof(double));  // translation and rotation matrix
	if (c.read<uint8_t>() != 0x88) return {};  // end-of-object flag
	if (c.read<uint8_t>())                     // hasPoints3D
	{
		const auto n = c.read<uint32_t>();
		if (!c.ok()) return {};
		if (n > kMaxImagePixels)
			return "the 3D scan declares " + std::to_string(n) +
			       " stored points, beyond the " +
			       std::to_string(kMaxImagePixels) + " a rawlog may hold";
		// x, y, z as float, pixel column and row as uint16
		c.skip(uint64_t{n} * (3 * sizeof(float) + 2 * sizeof(uint16_t)));
	}
	const bool hasRange = c.read<uint8_t>();
	c.skip(sizeof(float));  // rangeUnits
	if (!hasRange) return {};
	const uint64_t rows = c.read<uint32_t>(), cols = c.read<uint32_t>();
	if (!c.ok()) return {};
	if (rows > kMaxImageSide || cols > kMaxImageSide ||
	    rows * cols > kMaxImagePixels)
		return tooLarge("the 3D scan's depth image", rows, cols);
	return {};
}

}  // namespace bims
