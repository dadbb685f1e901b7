#include "scan_guard.h"

#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/rtti/CObject.h>
#include <opencv2/imgcodecs.hpp>

#include <cstring>
#include <optional>

namespace bims
{
namespace
{
/** The measurements (and data-present flags) an IMU observation keeps. */
constexpr uint64_t kImuFields = mrpt::obs::COUNT_IMU_DATA_FIELDS;
/** More observations than any sensory frame holds (a handful in practice):
 * beyond it the count is refused before the file is peeked that far (the
 * peek buffers what it is asked for). */
constexpr uint64_t kMaxFrameObservations = 1 << 20;

/** Reads MRPT's archive layout from peeked bytes; every read is bounds
 * checked and sets ok = false past the available bytes. */
class Cursor
{
 public:
	explicit Cursor(const PeekFn& peek) : peek_(peek) {}
	bool ok() const { return ok_; }
	size_t offset() const { return at_; }
	/** The bytes the file holds from the entry's start, as far as read. */
	size_t available() const { return size_; }

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
	/** Whether the file holds \a n more bytes from here (none consumed). */
	bool holds(uint64_t n)
	{
		if (!ok_) return false;
		if (at_ + n > size_)
		{
			const auto got = peek_(at_ + n);
			data_ = got.first;
			size_ = got.second;
		}
		return at_ + n <= size_;
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
		if (!holds(n)) ok_ = false;
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

std::string tooLarge(const std::string& owner, const std::string& what,
                     uint64_t rows, uint64_t cols)
{
	return "the " + owner + "'s " + what + " is " + std::to_string(rows) +
	       " x " + std::to_string(cols) + " (rows x columns), beyond the " +
	       std::to_string(kMaxImageSide) + " per side and " +
	       std::to_string(kMaxImagePixels) + " pixels a rawlog may hold";
}

/** The class MRPT's reader takes an object header's name for: a name with
 * a namespace must match whole (MRPT's own lookup drops the namespace, so
 * that a corrupt one would pass), one without (MRPT 1.x wrote its class
 * names so: "CObservation3DRangeScan", "CPose3D", "CMatrix" for today's
 * CMatrixF) is looked up as MRPT does. nullptr: a class MRPT does not
 * know. */
const mrpt::rtti::TRuntimeClassId* registered(const std::string& name)
{
	return mrpt::rtti::findRegisteredClass(
	    name, name.find("::") == std::string::npos);
}

/** Whether an object header's class name \a name stands for MRPT's class
 * \a full (its full name) as MRPT's reader takes it. */
bool isClass(const std::string& name, const char* full)
{
	const auto* id = registered(name);
	return id && id == mrpt::rtti::findRegisteredClass(full, false);
}

/** Whether an object of class \a id may stand where the walk is: the
 * observations, sensory frames and action collections of a rawlog at the
 * top level, observations alone inside a sensory frame. */
bool isEntryOf(const mrpt::rtti::TRuntimeClassId& id, bool inFrame)
{
	if (id.derivedFrom(CLASS_ID(mrpt::obs::CObservation))) return true;
	return !inFrame && (id.derivedFrom(CLASS_ID(mrpt::obs::CSensoryFrame)) ||
	                    id.derivedFrom(CLASS_ID(mrpt::obs::CActionCollection)));
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

	/** After run(): when a known object's walk stopped at the end of the
	 * file with no problem found, that is the problem (truncated): MRPT
	 * reads a size field the file cuts short as far as it goes, the rest
	 * of the value uninitialized, and allocates that (found by the
	 * fuzzer: 9 GB for a point count cut after 2 bytes). */
	void endedInside()
	{
		if (!problem.empty() || what_.empty() || c_.ok()) return;
		problem = "the " + what_ +
		          "'s layout runs past the end of the file (the entry holds " +
		          std::to_string(c_.available()) + " bytes)";
		truncated = true;
	}

	bool run()
	{
		uint8_t version = 0;
		const std::string cls = c_.header(version);
		const auto* id = cls.empty() ? nullptr : registered(cls);
		// a class MRPT does not know: it would read on as a typed object
		// and may allocate what the bytes declare (found by the fuzzer)
		if (!cls.empty() && !id)
		{
			problem = "an object of a class MRPT does not know ('" +
			          printable(cls) + "')";
			return false;
		}
		// Nor one of another class than a rawlog entry's: MRPT would read
		// it whole before the reader could refuse it, and reads the sizes
		// of a matrix, image or pose as they are (found by the fuzzer: a
		// top-level CPose3D whose CMatrixD declared 22 GB).
		if (id && !isEntryOf(*id, inFrame_))
		{
			problem = "an object of class '" + printable(cls) + "', not " +
			          (inFrame_ ? "an observation (a sensory frame holds "
			                      "observations only)"
			                    : "an observation, sensory frame or action "
			                      "collection");
			return false;
		}
		if (isClass(cls, "mrpt::obs::CObservation3DRangeScan"))
		{
			what_ = "3D scan";
			return scan(version);
		}
		if (isClass(cls, "mrpt::obs::CObservationIMU"))
		{
			what_ = "IMU observation";
			return imu(version);
		}
		if (isClass(cls, "mrpt::obs::CSensoryFrame") && !inFrame_)
		{
			what_ = "sensory frame";
			return sensoryFrame(version);
		}
		return false;
	}

 private:
	/** An IMU observation. Version 4 (MRPT 2.x): the sensor pose, a flag
	 * per measurement, the stamp, the measurements, the label. Versions 0-3
	 * (MRPT 1.x): the pose, the flags as a vector, the stamp, the
	 * measurements as a vector (of float in version 0, of double after),
	 * the label; MRPT allocates a vector's declared length before finding
	 * it longer than the kImuFields it keeps. */
	bool imu(uint8_t version)
	{
		if (version > 4) return false;  // MRPT refuses it
		if (!pose()) return false;
		if (version == 4)
		{
			for (uint64_t k = 0; k < kImuFields; k++)
				if (!flag("data-present flag " + std::to_string(k)))
					return false;
			c_.skip(sizeof(uint64_t) + kImuFields * sizeof(double));
		}
		else
		{
			// MRPT's vector<bool> reader takes any byte other than 0 as true
			if (!imuVector("data-present flags", 1)) return false;
			c_.skip(sizeof(uint64_t));  // timestamp
			if (!imuVector("measurements",
			               version == 0 ? sizeof(float) : sizeof(double)))
				return false;
		}
		return string("sensor label") && end();
	}
	/** A sensory frame (CSensoryFrame, MRPT 1.x's CSensorialFrame): from
	 * version 0 to 1 an ID, in version 0 a stamp, then the number of
	 * observations and each as an object. MRPT sizes its list by that number
	 * before reading any (the fuzzer's 1e9 made it allocate 16 GB): it may
	 * not exceed the bytes left, one at least per object. The observations
	 * are walked as at the top level. */
	bool sensoryFrame(uint8_t version)
	{
		if (version > 2) return false;                // MRPT refuses it
		if (version < 2) c_.skip(sizeof(uint32_t));   // ID
		if (version == 0) c_.skip(sizeof(uint64_t));  // stamp
		const uint64_t n = c_.read<uint32_t>();
		if (!c_.ok()) return false;
		if (n > kMaxFrameObservations)
		{
			problem = "the sensory frame declares " + std::to_string(n) +
			          " observations, more than the " +
			          std::to_string(kMaxFrameObservations) +
			          " a rawlog may hold";
			return false;
		}
		if (!c_.holds(n))
		{
			problem = "the sensory frame declares " + std::to_string(n) +
			          " observations, more than the bytes left in the file";
			truncated = true;
			return false;
		}
		inFrame_ = true;
		for (uint64_t k = 0; k < n; k++)
			if (!run()) return false;
		what_ = "sensory frame";
		return end();
	}
	/** A vector of an old IMU observation: its length (uint32), at most
	 * kImuFields, then the elements of \a elem bytes. */
	bool imuVector(const std::string& what, uint64_t elem)
	{
		const uint64_t n = c_.read<uint32_t>();
		if (!c_.ok()) return false;
		if (n > kImuFields)
		{
			problem = "the " + what_ + "'s " + what + " declare " +
			          std::to_string(n) + " entries, beyond the " +
			          std::to_string(kImuFields) + " MRPT keeps";
			return false;
		}
		return block(what, n * elem);
	}

	/** A 3D scan, each version (0-10) as MRPT 2.5.8 reads it: MRPT 2.1 on
	 * writes version 10, 1.9.9 and 2.0 version 9, MRPT 1.x 8 and before.
	 * Versions add fields (noted where read); 9 changed the depth image
	 * from a CMatrixF object of floats to raw uint16. */
	bool scan(uint8_t version)
	{
		if (version > 10) return false;  // MRPT refuses it
		scanVersion_ = version;
		c_.skip(sizeof(float));  // maxRange
		if (!pose()) return false;
		bool hasPoints = true;  // version 0 always stores points
		if (version >= 1)
		{
			const auto f = flag("has-points flag");
			if (!f) return false;
			hasPoints = *f;
		}
		if (hasPoints && !points(version)) return false;
		if (version >= 1 && !imagesAndCameras(version)) return false;
		c_.skip(sizeof(float) + sizeof(uint64_t));  // stdError, timestamp
		if (!string("sensor label")) return false;
		if (version >= 3)
			for (int k = 0; k < 2; k++)  // external points / range image files
				if (!flag("externally-stored flag") ||
				    !string("external file name"))
					return false;
		if (version >= 5 && !flag("range-is-depth flag")) return false;
		if (version >= 6) c_.skip(1);  // intensityImageChannel
		if (version >= 7)
		{
			const auto hasLabels = flag("has-labels flag");
			if (!hasLabels || (*hasLabels && !labels())) return false;
		}
		if (version >= 10)
		{
			const auto layers = c_.read<uint8_t>();
			for (unsigned k = 0; k < layers; k++)
				if (!string("layer name") ||
				    !matrix("extra depth layer", sizeof(uint16_t)))
					return false;
		}
		return c_.ok() && end();
	}

	/** A scan's stored points: their count, then x, y, z (float) of each,
	 * in version 0 a valid-range byte each, from version 8 their pixel
	 * column and row (uint16). */
	bool points(uint8_t version)
	{
		const auto n = c_.read<uint32_t>();
		if (!c_.ok()) return false;
		if (n > kMaxImagePixels)
		{
			problem = "the 3D scan declares " + std::to_string(n) +
			          " stored points, beyond the " +
			          std::to_string(kMaxImagePixels) + " a rawlog may hold";
			return false;
		}
		uint64_t each = 3 * sizeof(float);
		if (version == 0) each += 1;
		if (version >= 8) each += 2 * sizeof(uint16_t);
		return block("stored points", n * each);
	}

	/** A scan's images and camera models (version 1 on): the depth image
	 * (a CMatrixF object before version 9; from 9 its units, then rows,
	 * cols and raw uint16), the intensity and confidence images, the depth
	 * camera's model (version 2 on), the intensity camera's model and pose
	 * (version 4 on). */
	bool imagesAndCameras(uint8_t version)
	{
		const auto hasRange = flag("has-range flag");
		if (!hasRange) return false;
		if (version >= 9) c_.skip(sizeof(float));  // rangeUnits
		if (*hasRange &&
		    !(version >= 9 ? matrix("depth image", sizeof(uint16_t))
		                   : matrixObject("depth image", "mrpt::math::CMatrixF",
		                                  sizeof(float))))
			return false;
		const auto hasIntensity = flag("has-intensity flag");
		if (!hasIntensity || (*hasIntensity && !image("intensity image")))
			return false;
		const auto hasConfidence = flag("has-confidence flag");
		if (!hasConfidence || (*hasConfidence && !image("confidence image")))
			return false;
		if (version >= 2 && !camera()) return false;
		return version < 4 || (camera() && pose());
	}

	/** rows, cols (uint32), then rows * cols elements of \a elem bytes. */
	bool matrix(const std::string& what, uint64_t elem)
	{
		const uint64_t rows = c_.read<uint32_t>(), cols = c_.read<uint32_t>();
		if (!c_.ok()) return false;
		if (!imageSizeWithinLimits(rows, cols))
		{
			problem = tooLarge(what_, what, rows, cols);
			return false;
		}
		return block(what, rows * cols * elem);
	}
	/** A matrix stored as an object of class \a cls (CMatrixF: float
	 * elements, CMatrixD: double; version 0, their only one): a matrix(). */
	bool matrixObject(const std::string& what, const char* cls, uint64_t elem)
	{
		const auto v = object(cls);
		if (!v || *v != 0) return false;  // another version: MRPT refuses it
		return matrix(what, elem) && end();
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
	/** A JPEG-stored image: the size its frame header declares must pass
	 * the image limits (OpenCV and MRPT allocate the whole image from it
	 * before decoding), and its bytes must decode (OpenCV, whose libjpeg
	 * error handler returns): MRPT decodes them with libjpeg's default
	 * handler, which ends the whole process on bytes that are no JPEG
	 * (found by the fuzzer). */
	bool jpeg(const std::string& what)
	{
		const auto start = c_.offset();
		if (!string(what)) return false;
		const auto bytes = c_.bytes(start + sizeof(uint32_t), c_.offset());
		if (!bytes) return false;
		const size_t n = c_.offset() - start - 4;
		// OpenCV decodes any format it knows (a PNG, a PPM declaring a
		// gigapixel image), MRPT only JPEG: its start of image first
		const bool soi = n >= 2 && bytes[0] == 0xff && bytes[1] == 0xd8;
		if (!soi)
		{
			problem = "the " + what_ + "'s " + what +
			          " is stored as JPEG but its bytes do not decode (no "
			          "JPEG start of image)";
			return false;
		}
		if (const auto h = imageHeader(bytes, n);
		    h && !imageSizeWithinLimits(h->height, h->width))
		{
			problem = tooLarge(what_, what, h->height, h->width);
			return false;
		}
		const cv::Mat raw(1, static_cast<int>(n), CV_8UC1,
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
	/** An inner object's header, where every MRPT version writes one of
	 * class \a cls: its version, or nullopt to stop (the bytes end, or
	 * another class or no object is there: a mismatch). */
	std::optional<uint8_t> object(const char* cls)
	{
		uint8_t v = 0;
		const size_t at = c_.offset();
		if (isClass(c_.header(v), cls)) return v;
		const char* name = std::strrchr(cls, ':');
		mismatch(std::string("a ") + (name ? name + 1 : cls), at);
		return std::nullopt;
	}
	/** A CPose3D: in version 0 a 4 x 4 CMatrixF, in 1 a 4 x 4 CMatrixD
	 * (MRPT checks the size once read), in 2 the translation and a
	 * quaternion (7 doubles), in 3 the translation and the rotation matrix
	 * (12). */
	bool pose()
	{
		const auto v = object("mrpt::poses::CPose3D");
		if (!v) return false;
		switch (*v)
		{
			case 0:
				if (!matrixObject("pose matrix", "mrpt::math::CMatrixF",
				                  sizeof(float)))
					return false;
				break;
			case 1:
				if (!matrixObject("pose matrix", "mrpt::math::CMatrixD",
				                  sizeof(double)))
					return false;
				break;
			case 2:
				c_.skip(7 * sizeof(double));
				break;
			case 3:
				c_.skip(12 * sizeof(double));
				break;
			default:
				return false;  // MRPT refuses it
		}
		return end();
	}
	/** A TCamera (versions 0-6): the focal length [m], 5 distortion
	 * parameters (8 from version 3), the intrinsic matrix (a 3 x 3 CMatrixD
	 * before version 4, then fx fy cx cy), in version 0 an unused 1 x 5
	 * CMatrixD, the image size (version 2 on; MRPT corrects it from the
	 * depth image), the name (5 on), the distortion model (6 on). */
	bool camera()
	{
		const auto v = object("mrpt::img::TCamera");
		if (!v || *v > 6) return false;  // another version: MRPT refuses it
		c_.skip((1 + (*v >= 3 ? 8 : 5)) * sizeof(double));
		if (*v < 4)
		{
			if (!matrixObject("camera matrix", "mrpt::math::CMatrixD",
			                  sizeof(double)))
				return false;
		}
		else
			c_.skip(4 * sizeof(double));
		if (*v == 0 && !matrixObject("camera distortion vector",
		                             "mrpt::math::CMatrixD", sizeof(double)))
			return false;
		if (*v >= 2) c_.skip(2 * sizeof(uint32_t));
		if (*v >= 5 && !string("camera name")) return false;
		if (*v >= 6) c_.skip(1);
		return end();
	}
	/** A CImage, each version as MRPT 2.5.8 reads it: 0 raw pixels, 1 a
	 * JPEG, 2-9 (from 6: an external file's name, or) grey pixels or a
	 * colour JPEG (from 7 after its size; a negative size: raw BGR
	 * pixels), 100 (written by an MRPT without OpenCV) an external file's
	 * name or nothing. */
	bool image(const std::string& what)
	{
		const size_t at = c_.offset();
		const auto v = object("mrpt::img::CImage");
		if (!v) return false;
		// a scan of version 10 (MRPT 2.1 on) holds MRPT 2.x's images only
		// (an older image version made MRPT decode bytes as JPEG with
		// libjpeg's exiting error handler: found by the fuzzer)
		if (scanVersion_ >= 10 && *v != 9)
			return mismatch("a CImage of version 9, as MRPT 2.x writes", at);
		if (*v == 0) return rawImage(what) && end();
		if (*v == 1) return jpeg(what) && end();
		if (*v > 9 && *v != 100) return false;  // MRPT refuses it
		if (*v >= 6)
		{
			const auto external = flag(what + "'s external-file flag");
			if (!external) return false;
			if (*external) return string(what + " file name") && end();
			if (*v == 100) return end();
		}
		if (!c_.read<uint8_t>())  // colour: any byte but 0
			return greyImage(what, *v) && end();
		if (*v >= 7)
		{
			const auto w = c_.read<int32_t>(), h = c_.read<int32_t>();
			if (!c_.ok()) return false;
			if (w < 0 && h < 0)  // raw BGR
			{
				const uint64_t rw = -int64_t{w}, rh = -int64_t{h};
				if (!imageSizeWithinLimits(rh, rw))
				{
					problem = tooLarge(what_, what, rh, rw);
					return false;
				}
				return block(what, 3 * rw * rh) && end();
			}
			if (w < 1 || h < 1) return end();  // empty: no pixels stored
		}
		return jpeg(what) && end();
	}
	/** A grey image's pixels (CImage versions 2-9): width, height, origin,
	 * size in bytes (int32), from version 9 the pixel depth, then, unless
	 * ZIP-compressed (which MRPT 2.x no longer reads), the bytes. MRPT
	 * allocates width x height pixels of that depth before it checks the
	 * size against them. */
	bool greyImage(const std::string& what, uint8_t version)
	{
		const uint64_t w = c_.read<uint32_t>(), h = c_.read<uint32_t>();
		c_.skip(sizeof(int32_t));  // origin
		const uint64_t size = c_.read<uint32_t>();
		const int32_t depth = version >= 9 ? c_.read<int32_t>() : 0;
		if (!c_.ok()) return false;
		if (!imageSizeWithinLimits(h, w))
		{
			problem = tooLarge(what_, what, h, w);
			return false;
		}
		// bytes per pixel of MRPT's PixelDepth: D8U D8S D16U D16S D32S
		// D32F D64F
		static constexpr uint64_t kDepthBytes[] = {1, 1, 2, 2, 4, 4, 8};
		if (depth < 0 || depth > 6)
		{
			problem = "the " + what_ + "'s " + what + " declares pixel depth " +
			          std::to_string(depth) + ", none of MRPT's (0 to 6)";
			return false;
		}
		const uint64_t bytes = w * h * kDepthBytes[depth];
		if (size != bytes)
		{
			problem = "the " + what_ + "'s " + what + " declares " +
			          std::to_string(size) + " bytes for " + std::to_string(w) +
			          " x " + std::to_string(h) + " pixels of " +
			          std::to_string(kDepthBytes[depth]) + " bytes (" +
			          std::to_string(bytes) + ")";
			return false;
		}
		bool zip = version == 3 || (version == 4 && size > 16 * 1024);
		if (version >= 5)
		{
			const auto z = flag(what + "'s ZIP flag");
			if (!z) return false;
			zip = *z;
		}
		if (zip)
		{
			problem = "the " + what_ + "'s " + what +
			          " is stored ZIP-compressed, which MRPT 2.x no longer "
			          "reads";
			return false;
		}
		return block(what, size);
	}
	/** An image of CImage version 0: width, height, channels (uint32),
	 * origin (uint8), size in bytes (uint32), the bytes. */
	bool rawImage(const std::string& what)
	{
		const uint64_t w = c_.read<uint32_t>(), h = c_.read<uint32_t>(),
		               channels = c_.read<uint32_t>();
		c_.skip(1);
		const uint64_t size = c_.read<uint32_t>();
		if (!c_.ok()) return false;
		if (!imageSizeWithinLimits(h, w))
		{
			problem = tooLarge(what_, what, h, w);
			return false;
		}
		if (channels < 1 || channels > 4)
		{
			problem = "the " + what_ + "'s " + what + " declares " +
			          std::to_string(channels) + " channels, not 1 to 4";
			return false;
		}
		// MRPT allocates the pixels and reads the declared bytes into them:
		// more would be written past them, fewer leave an allocation the
		// file does not hold
		if (size != w * h * channels)
		{
			problem = "the " + what_ + "'s " + what + " declares " +
			          std::to_string(size) + " bytes, not its " +
			          std::to_string(w) + " x " + std::to_string(h) + " x " +
			          std::to_string(channels) + " pixels' " +
			          std::to_string(w * h * channels);
			return false;
		}
		return block(what, size);
	}
	/** Pixel labels: version, the label bits' bytes (1 to 8: MRPT keeps
	 * 3 in 4-byte and 5 to 7 in 8-byte elements), the label image (rows,
	 * cols, then that many elements), then the label names as
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
		if (bytes < 1 || bytes > 8)
		{
			problem = "the " + what_ + "'s pixel labels declare " +
			          std::to_string(bytes) + " bytes per pixel, not 1 to 8";
			return false;
		}
		const uint64_t elem = bytes <= 2 ? bytes : bytes <= 4 ? 4 : 8;
		if (!matrix("pixel-label image", elem)) return false;
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
	std::string what_;      ///< "3D scan", "IMU observation"
	int scanVersion_ = 0;   ///< of the 3D scan walked
	bool inFrame_ = false;  ///< inside a sensory frame (they do not nest)
};
}  // namespace

std::string checkSerializedSizes(const PeekFn& peek, bool* truncated)
{
	ObservationWalker w(peek);
	w.run();
	w.endedInside();
	if (truncated) *truncated = w.truncated;
	return w.problem;
}

}  // namespace bims
