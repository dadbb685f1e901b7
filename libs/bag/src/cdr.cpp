#include <bims/bag/cdr.h>

#include <bims/bag/bag_import.h>
#include <mrpt/core/format.h>

#include <cstring>
#include <stdexcept>

#include "messages.h"

namespace bims::bag::cdr
{
namespace
{
using std::runtime_error;

/** Reads a CDR message's fields in order: each primitive aligned to its
 * size from the end of the encapsulation header, each length checked
 * against the bytes left. */
class Reader
{
 public:
	Reader(const uint8_t* p, size_t n) : p_(p), n_(n)
	{
		if (n < 4)
			throw runtime_error(mrpt::format(
			    "%zu bytes: shorter than CDR's 4-byte encapsulation header",
			    n));
		// representation identifier (big-endian 16 bits), then options
		const unsigned id = unsigned(p[0]) << 8 | p[1];
		if (id == 0x0000)
			big_ = true;
		else if (id == 0x0001)
			big_ = false;
		else
			throw runtime_error(mrpt::format(
			    "its encapsulation header 0x%04x is not CDR_BE or CDR_LE "
			    "(XCDR2 and parameter lists are not read)",
			    id));
		i_ = 4;
	}

	/** Skips padding to a multiple of \a a from the header's end. */
	void align(size_t a, const char* what)
	{
		const size_t pad = (a - (i_ - 4) % a) % a;
		need(pad, what);
		i_ += pad;
	}
	template <typename T>
	T get(const char* what)
	{
		align(sizeof(T), what);
		need(sizeof(T), what);
		uint8_t b[sizeof(T)];
		std::memcpy(b, p_ + i_, sizeof(T));
		if (big_)
			for (size_t k = 0; k < sizeof(T) / 2; k++)
				std::swap(b[k], b[sizeof(T) - 1 - k]);
		T v;
		std::memcpy(&v, b, sizeof(T));
		i_ += sizeof(T);
		return v;
	}
	double f64(const char* what) { return get<double>(what); }
	uint32_t u32(const char* what) { return get<uint32_t>(what); }
	std::string string(const char* what)
	{
		const uint32_t k = u32(what);
		need(k, what);
		const char* s = reinterpret_cast<const char*>(p_ + i_);
		i_ += k;
		// its length counts the terminating NUL
		return std::string(s, k > 0 && s[k - 1] == '\0' ? k - 1 : k);
	}
	/** A sequence<uint8>: where its bytes are, not copied. */
	const uint8_t* bytes(size_t& k, const char* what)
	{
		k = u32(what);
		need(k, what);
		const uint8_t* at = p_ + i_;
		i_ += k;
		return at;
	}
	void f64s(double* out, size_t k, const char* what)
	{
		for (size_t j = 0; j < k; j++) out[j] = f64(what);
	}
	/** std_msgs/Header: its stamp [s], frame_id skipped. */
	double header()
	{
		const HeaderTime h = headerTime();
		(void)string("header's frame_id");
		return stampSeconds(h.sec, h.nsec);
	}
	/** std_msgs/Header's stamp, checked. */
	HeaderTime headerTime()
	{
		const int32_t sec = get<int32_t>("header's stamp");
		const uint32_t nsec = u32("header's stamp");
		// (nanoseconds of a second or more: carried into the seconds by
		// stampSeconds, as ROS normalises them)
		if (sec < 0)
			throw runtime_error(mrpt::format(
			    "its header's stamp %d s %u ns is not a time: corrupt", sec,
			    nsec));
		return {static_cast<uint32_t>(sec), nsec};
	}

 private:
	void need(uint64_t k, const char* what)
	{
		if (k > n_ - i_)
			throw runtime_error(mrpt::format(
			    "it ends inside its %s (%zu bytes, %llu more needed): "
			    "shorter than its type",
			    what, n_, static_cast<unsigned long long>(k - (n_ - i_))));
	}

	const uint8_t* p_;
	size_t n_, i_ = 0;
	bool big_ = false;
};
}  // namespace

double headerStamp(const uint8_t* p, size_t n)
{
	Reader r(p, n);
	return r.header();
}

HeaderTime headerTime(const uint8_t* p, size_t n)
{
	Reader r(p, n);
	return r.headerTime();
}

ImageView image(const uint8_t* p, size_t n)
{
	Reader r(p, n);
	ImageView v;
	v.t = r.header();
	v.height = r.u32("height");
	v.width = r.u32("width");
	v.encoding = r.string("encoding");
	v.bigEndian = r.get<uint8_t>("is_bigendian") != 0;
	v.step = r.u32("step");
	v.data = r.bytes(v.size, "data");
	return v;
}

CompressedView compressedImage(const uint8_t* p, size_t n)
{
	Reader r(p, n);
	CompressedView v;
	v.t = r.header();
	v.format = r.string("format");
	v.data = r.bytes(v.size, "data");
	return v;
}

CameraInfoView cameraInfo(const uint8_t* p, size_t n)
{
	Reader r(p, n);
	CameraInfoView v;
	(void)r.header();
	v.height = r.u32("height");
	v.width = r.u32("width");
	v.distortionModel = r.string("distortion_model");
	const uint32_t nd = r.u32("d");
	// every coefficient there before any is stored
	if (nd > n / 8)
		throw runtime_error(mrpt::format(
		    "its d declares %u coefficients, the message has %zu bytes: "
		    "corrupt",
		    nd, n));
	v.D.resize(nd);
	r.f64s(v.D.data(), nd, "d");
	r.f64s(v.K, 9, "k");
	double rest[12];
	r.f64s(rest, 9, "r");
	r.f64s(rest, 12, "p");
	(void)r.u32("binning_x");
	(void)r.u32("binning_y");
	for (const char* f :
	     {"roi's x_offset", "roi's y_offset", "roi's height", "roi's width"})
		(void)r.u32(f);
	(void)r.get<uint8_t>("roi's do_rectify");
	return v;
}

ImuSample imu(const uint8_t* p, size_t n)
{
	Reader r(p, n);
	const double t = r.header();
	double q[4], cov[9], w[3], wCov[9], a[3], aCov[9];
	r.f64s(q, 4, "orientation");
	r.f64s(cov, 9, "orientation_covariance");
	r.f64s(w, 3, "angular_velocity");
	r.f64s(wCov, 9, "angular_velocity_covariance");
	r.f64s(a, 3, "linear_acceleration");
	r.f64s(aCov, 9, "linear_acceleration_covariance");
	ImuSample s = imuSampleOf(t, w, wCov[0], a, aCov[0]);
	// covariance -1: no orientation (the message's convention)
	if (cov[0] != -1)
	{
		s.hasOrientation = true;
		for (int k = 0; k < 4; k++) s.q[k] = q[k];
	}
	return s;
}

ImuSample magneticField(const uint8_t* p, size_t n)
{
	Reader r(p, n);
	const double t = r.header();
	double m[3], cov[9];
	r.f64s(m, 3, "magnetic_field");
	r.f64s(cov, 9, "magnetic_field_covariance");
	return magSampleOf(t, m);
}

float float32(const uint8_t* p, size_t n)
{
	Reader r(p, n);
	return r.get<float>("data");
}

TransformView transform(const uint8_t* p, size_t n)
{
	Reader r(p, n);
	TransformView v;
	r.f64s(v.t, 3, "translation");
	r.f64s(v.q, 4, "rotation");
	return v;
}

}  // namespace bims::bag::cdr
