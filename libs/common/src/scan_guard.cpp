#include "scan_guard.h"

#include <mrpt/rtti/CObject.h>
#include <opencv2/imgcodecs.hpp>

#include <cstring>
#include <optional>

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
	/** The bytes from offset \a from to \a to (already walked past), or
	 * nullptr. */
	const uint8_t* bytes(size_t from, size_t to)
	{
		if (!ok_ || to > size_ || from > to) return nullptr;
		return data_ + from;
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

/** \a s with bytes outside printable ASCII as '?'. */
std::string printable(std::string s)
{
	for (char& ch : s)
		if (ch < 0x20 || ch > 0x7e) ch = '?';
	return s;
}

/** Whether a rows x cols image passes the limits. */
bool saneSize(uint64_t rows, uint64_t cols)
{
	return rows <= kMaxImageSide && cols <= kMaxImageSide &&
	       rows * cols <= kMaxImagePixels;
}

std::string tooLarge(const std::string& what, uint64_t rows, uint64_t cols)
{
	return "the 3D scan's " + what + " is " + std::to_string(rows) + " x " +
	       std::to_string(cols) + " (rows x columns), beyond the " +
	       std::to_string(kMaxImageSide) + " per side and " +
	       std::to_string(kMaxImagePixels) + " pixels a rawlog may hold";
}

/** Walks a serialized observation field by field. Each step returns false
 * to stop: with `problem` set when a declared size is insane, empty when the
 * bytes end or hold a layout this walker does not know (MRPT then decides). */
class ObservationWalker
{
 public:
	explicit ObservationWalker(const PeekFn& peek) : c_(peek) {}
	std::string problem;
	bool truncated = false;  ///< the problem is the end of the file

	bool run()
	{
		uint8_t version = 0;
		const std::string cls = c_.header(version);
		// a class MRPT does not know: it would read on as a typed object
		// and may allocate what the bytes declare (found by the fuzzer). A
		// name with a namespace must match whole (MRPT's own lookup drops
		// it); one without (older rawlogs) is looked up as MRPT does.
		const bool ns = cls.find("::") != std::string::npos;
		if (!cls.empty() && !mrpt::rtti::findRegisteredClass(cls, !ns))
		{
			problem = "an object of a class MRPT does not know ('" +
			          printable(cls) + "')";
			return false;
		}
		if (cls == "mrpt::obs::CObservation3DRangeScan")
		{
			what_ = "3D scan";
			return scan(version);
		}
		if (cls == "mrpt::obs::CObservationIMU")
		{
			what_ = "IMU observation";
			return imu(version);
		}
		return false;
	}

 private:
	/** MRPT 2.x's layout (version 4): the sensor pose, 31 flags of the
	 * data present, the stamp, 31 measurements, the label. */
	bool imu(uint8_t version)
	{
		if (version != 4 || !pose()) return false;
		for (int k = 0; k < 31; k++)
			if (!flag("data-present flag " + std::to_string(k))) return false;
		c_.skip(sizeof(uint64_t) + 31 * sizeof(double));
		return string("sensor label") && end();
	}

	bool scan(uint8_t version)
	{
		if (version != 9 && version != 10) return false;
		scanVersion_ = version;
		c_.skip(sizeof(float));  // maxRange
		if (!pose()) return false;
		const auto hasPoints = flag("has-points flag");
		if (!hasPoints) return false;
		if (*hasPoints)
		{
			const auto n = c_.read<uint32_t>();
			if (!c_.ok()) return false;
			if (n > kMaxImagePixels)
			{
				problem = "the 3D scan declares " + std::to_string(n) +
				          " stored points, beyond the " +
				          std::to_string(kMaxImagePixels) +
				          " a rawlog may hold";
				return false;
			}
			// x, y, z as float, pixel column and row as uint16
			if (!block("stored points", uint64_t{n} * (3 * sizeof(float) +
			                                           2 * sizeof(uint16_t))))
				return false;
		}
		const auto hasRange = flag("has-range flag");
		if (!hasRange) return false;
		c_.skip(sizeof(float));  // rangeUnits
		if (*hasRange && !matrix("depth image", sizeof(uint16_t))) return false;
		const auto hasIntensity = flag("has-intensity flag");
		if (!hasIntensity || (*hasIntensity && !image("intensity image")))
			return false;
		const auto hasConfidence = flag("has-confidence flag");
		if (!hasConfidence || (*hasConfidence && !image("confidence image")))
			return false;
		if (!camera() || !camera() || !pose()) return false;
		c_.skip(sizeof(float) + sizeof(uint64_t));  // stdError, timestamp
		if (!string("sensor label")) return false;
		for (int k = 0; k < 2; k++)  // external points / range image files
			if (!flag("externally-stored flag") ||
			    !string("external file name"))
				return false;
		if (!flag("range-is-depth flag")) return false;
		c_.skip(1);  // intensityImageChannel
		const auto hasLabels = flag("has-labels flag");
		if (!hasLabels || (*hasLabels && !labels())) return false;
		if (version >= 10)
		{
			const auto layers = c_.read<uint8_t>();
			for (unsigned k = 0; k < layers; k++)
				if (!string("layer name") ||
				    !matrix("extra depth layer", sizeof(uint16_t)))
					return false;
		}
		return c_.ok();
	}

	/** rows, cols (uint32), then rows * cols elements of \a elem bytes. */
	bool matrix(const std::string& what, uint64_t elem)
	{
		const uint64_t rows = c_.read<uint32_t>(), cols = c_.read<uint32_t>();
		if (!c_.ok()) return false;
		if (!saneSize(rows, cols))
		{
			problem = tooLarge(what, rows, cols);
			return false;
		}
		return block(what, rows * cols * elem);
	}
	/** A string or byte block: its length (uint32), then the bytes. */
	bool string(const std::string& what)
	{
		const uint64_t n = c_.read<uint32_t>();
		if (!c_.ok()) return false;
		if (n > kMaxStringBytes)
		{
			problem = "the " + what_ + "'s " + what + " declares " +
			          std::to_string(n) + " bytes, beyond the " +
			          std::to_string(kMaxStringBytes) + " a rawlog may hold";
			return false;
		}
		return block(what, n);
	}
	/** A JPEG-stored image: its bytes must decode (OpenCV, whose libjpeg
	 * error handler returns): MRPT decodes them with libjpeg's default
	 * handler, which ends the whole process on bytes that are no JPEG
	 * (found by the fuzzer). */
	bool jpeg(const std::string& what)
	{
		const auto start = c_.offset();
		if (!string(what)) return false;
		const auto bytes = c_.bytes(start + sizeof(uint32_t), c_.offset());
		if (!bytes) return false;
		const cv::Mat raw(1, static_cast<int>(c_.offset() - start - 4), CV_8UC1,
		                  const_cast<uint8_t*>(bytes));
		bool ok = false;
		try
		{
			ok = !raw.empty() &&
			     !cv::imdecode(raw, cv::IMREAD_UNCHANGED).empty();
		}
		catch (const cv::Exception&)
		{
		}
		if (ok) return true;
		problem = "the " + what_ + "'s " + what +
		          " is stored as JPEG but its bytes do not decode";
		return false;
	}
	/** \a bytes of a block the object declared: when the file ends before
	 * them, that is the problem (truncated), found before MRPT allocates
	 * the block. */
	bool block(const std::string& what, uint64_t bytes)
	{
		if (!c_.ok()) return false;
		c_.skip(bytes);
		if (c_.ok()) return true;
		problem = "the " + what_ + "'s " + what + " (" + std::to_string(bytes) +
		          " bytes) runs past the end of the file";
		truncated = true;
		return false;
	}
	/** A bool the object stores as a byte: 0 or 1 (MRPT reads it into a
	 * bool, any other byte is undefined behaviour where it is read: found
	 * by the fuzzer). nullopt: stop (the problem set, or the bytes end). */
	std::optional<bool> flag(const std::string& what)
	{
		const auto b = c_.read<uint8_t>();
		if (!c_.ok()) return std::nullopt;
		if (b > 1)
		{
			problem = "the " + what_ + "'s " + what + " is " +
			          std::to_string(b) + ", not 0 or 1";
			return std::nullopt;
		}
		return b == 1;
	}
	/** An object's end flag. */
	bool end()
	{
		const auto b = c_.read<uint8_t>();
		return c_.ok() &&
		       (b == 0x88 || mismatch("an object's end flag", c_.offset() - 1));
	}
	/** Another class (or no object) where every MRPT version writes the
	 * named one, or no end flag: corrupt (MRPT itself would read on and may
	 * allocate what the bytes declare). Returns false. */
	bool mismatch(const std::string& where, size_t at)
	{
		if (c_.ok())
			problem = "the " + what_ + " does not hold MRPT's layout (" +
			          where + " expected at byte " + std::to_string(at) +
			          " of the entry)";
		return false;
	}
	bool pose()
	{
		uint8_t v = 0;
		const size_t at = c_.offset();
		if (c_.header(v) != "mrpt::poses::CPose3D")
			return mismatch("a CPose3D", at);
		if (v != 3) return false;      // another MRPT's: MRPT decides
		c_.skip(12 * sizeof(double));  // translation and rotation matrix
		return end();
	}
	bool camera()
	{
		uint8_t v = 0;
		const size_t at = c_.offset();
		if (c_.header(v) != "mrpt::img::TCamera")
			return mismatch("a TCamera", at);
		if (v != 6) return false;  // another MRPT's: MRPT decides
		// 13 doubles (distortion, focal length [m], fx fy cx cy), the
		// image size (MRPT corrects it from the depth image), the name, the
		// distortion model
		c_.skip(13 * sizeof(double) + 2 * sizeof(uint32_t));
		if (!string("camera name")) return false;
		c_.skip(1);
		return end();
	}
	bool image(const std::string& what)
	{
		uint8_t v = 0;
		const size_t at = c_.offset();
		if (c_.header(v) != "mrpt::img::CImage")
			return mismatch("a CImage", at);
		// another MRPT's: MRPT decides; but a scan of version 10 (MRPT
		// 2.1 on) holds MRPT 2.x's images only (an older image version
		// made MRPT decode bytes as JPEG with libjpeg's exiting error
		// handler: found by the fuzzer)
		if (v != 9)
			return scanVersion_ >= 10
			           ? mismatch("a CImage of version 9, as MRPT 2.x writes",
			                      at)
			           : false;
		if (c_.read<uint8_t>())
			return string(what + " file name") && end();  // external file
		if (!c_.read<uint8_t>())  // grey: w h origin size depth zip data
		{
			const uint64_t w = c_.read<uint32_t>(), h = c_.read<uint32_t>();
			c_.skip(sizeof(int32_t));
			const auto size = c_.read<uint32_t>();
			c_.skip(sizeof(int32_t));
			if (!c_.ok()) return false;
			if (!saneSize(h, w))
			{
				problem = tooLarge(what, h, w);
				return false;
			}
			if (c_.read<uint8_t>()) return false;  // zip: MRPT refuses it
			return block(what, size) && end();
		}
		const auto w = c_.read<int32_t>(), h = c_.read<int32_t>();
		if (!c_.ok()) return false;
		if (w >= 1 && h >= 1) return jpeg(what) && end();
		if (w < 0 && h < 0)  // raw BGR
		{
			const uint64_t rw = -int64_t{w}, rh = -int64_t{h};
			if (!saneSize(rh, rw))
			{
				problem = tooLarge(what, rh, rw);
				return false;
			}
			if (!block(what, 3 * rw * rh)) return false;
		}
		return end();
	}
	/** Pixel labels: version, bytes per pixel (1, 2, 4 or 8), the label
	 * image (rows, cols, then that many elements), then the label names as
	 * MRPT writes a std::map<uint32_t, std::string>: "std::map", the key and
	 * value type names, the count, then key and name per entry. MRPT's
	 * reader allocates the label image with `new` before reading on, and
	 * leaks it (up to 15 MB) when anything after it throws: every part is
	 * checked here so that it does not. */
	bool labels()
	{
		const auto version = c_.read<uint8_t>();
		const auto bytes = c_.read<uint8_t>();
		if (!c_.ok()) return false;
		if (version != 1) return false;  // another MRPT's: MRPT decides
		if (bytes != 1 && bytes != 2 && bytes != 4 && bytes != 8)
		{
			problem = "the " + what_ + "'s pixel labels declare " +
			          std::to_string(bytes) +
			          " bytes per pixel, not 1, 2, 4 or 8";
			return false;
		}
		if (!matrix("pixel-label image", bytes)) return false;
		for (const char* type : {"std::map", "uint32_t", "std::string"})
		{
			const auto at = c_.offset();
			const uint64_t n = c_.read<uint32_t>();
			if (!c_.ok()) return false;
			const std::string expected =
			    std::string("the pixel-label names' type '") + type + "'";
			if (n != std::strlen(type)) return mismatch(expected, at);
			const auto from = c_.offset();
			c_.skip(n);
			const auto name = c_.bytes(from, c_.offset());
			if (!name) return false;  // the bytes end
			if (std::memcmp(name, type, n)) return mismatch(expected, at);
		}
		const uint64_t names = c_.read<uint32_t>();
		for (uint64_t k = 0; k < names && c_.ok(); k++)
		{
			c_.skip(sizeof(uint32_t));  // the label's bit
			if (!string("pixel-label name")) break;
		}
		if (c_.ok() || !problem.empty()) return c_.ok();
		problem = "the " + what_ + "'s pixel-label names (" +
		          std::to_string(names) +
		          " declared) run past the end of "
		          "the file";
		truncated = true;
		return false;
	}

	Cursor c_;
	std::string what_;     ///< "3D scan", "IMU observation"
	int scanVersion_ = 0;  ///< of the 3D scan walked
};
}  // namespace

std::string checkSerializedSizes(const PeekFn& peek, bool* truncated)
{
	ObservationWalker w(peek);
	w.run();
	if (truncated) *truncated = w.truncated;
	return w.problem;
}

}  // namespace bims
