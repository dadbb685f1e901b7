#include <bims/common/config.h>
#include <bims/grab/openni2_source.h>

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/core/bits_math.h>
#include <mrpt/img/CImage.h>

#include <OpenNI.h>

#include <cmath>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace bims::grab
{
namespace
{
std::string oniError(const std::string& what)
{
	std::string e = openni::OpenNI::getExtendedError();
	while (!e.empty() && (e.back() == '\n' || e.back() == ' ')) e.pop_back();
	while (!e.empty() && (e.front() == '\t' || e.front() == ' ')) e.erase(0, 1);
	return "OpenNI2: " + what + (e.empty() ? "" : ": " + e);
}

void initOpenNI()
{
	// Initialised once and never shut down: OpenNI::shutdown() crashes in
	// the Dummy driver's thread (Debian OpenNI2 2.2.0.33); process exit
	// releases everything.
	static std::once_flag once;
	static openni::Status rc = openni::STATUS_OK;
	std::call_once(once, [] { rc = openni::OpenNI::initialize(); });
	if (rc != openni::STATUS_OK)
		throw std::runtime_error(oniError("initialisation failed"));
}

void chooseMode(openni::VideoStream& s, int w, int h, int fps, const char* what)
{
	if (w <= 0 && h <= 0 && fps <= 0) return;
	const auto& modes = s.getSensorInfo().getSupportedVideoModes();
	std::ostringstream have;
	for (int i = 0; i < modes.getSize(); ++i)
	{
		const auto& m = modes[i];
		have << " " << m.getResolutionX() << "x" << m.getResolutionY() << "@"
		     << m.getFps();
		if ((w <= 0 || m.getResolutionX() == w) &&
		    (h <= 0 || m.getResolutionY() == h) &&
		    (fps <= 0 || m.getFps() == fps))
		{
			const auto pf = m.getPixelFormat();
			const bool ok = std::string(what) == "depth"
			                    ? (pf == openni::PIXEL_FORMAT_DEPTH_1_MM ||
			                       pf == openni::PIXEL_FORMAT_DEPTH_100_UM)
			                    : pf == openni::PIXEL_FORMAT_RGB888;
			if (ok && s.setVideoMode(m) == openni::STATUS_OK) return;
		}
	}
	throw std::runtime_error("OpenNI2: no " + std::string(what) + " mode " +
	                         std::to_string(w) + "x" + std::to_string(h) + "@" +
	                         std::to_string(fps) +
	                         "; the device offers:" + have.str());
}
}  // namespace

void OpenNI2Params::loadFromConfigFile(const mrpt::config::CConfigFileBase& c,
                                       const std::string& s)
{
	ConfigSection sec(c, s, true);
	sec.allow("driver");
	sensorLabel = sec.getString("sensorLabel", sensorLabel);
	uri = sec.getString("device_uri", uri);
	width = static_cast<int>(sec.getInt("width", width, 0, 8192));
	height = static_cast<int>(sec.getInt("height", height, 0, 8192));
	fps = static_cast<int>(sec.getInt("fps", fps, 0, 1000));
	registerDepth = sec.getBool("register_depth", registerDepth);
	fallbackHfovDeg =
	    sec.getDouble("fallback_hfov_deg", fallbackHfovDeg, 1, 179);
	timeoutMs = static_cast<int>(sec.getInt("timeout_ms", timeoutMs, 1, 60000));
	maxRangeM = sec.getDouble("max_range", maxRangeM, 0.1, 100);
	sec.finish();
}

struct OpenNI2Source::Impl
{
	openni::Device dev;
	openni::VideoStream depth, colour;
	bool hasColour = false;
	openni::VideoFrameRef lastColour;
	ClockMapper clock;
	double fx = 0, fy = 0, cx = 0, cy = 0;
	double rangeUnits = 0.001;
	int w = 0, h = 0;
	std::string describe;

	~Impl()
	{
		if (depth.isValid()) depth.stop(), depth.destroy();
		if (colour.isValid()) colour.stop(), colour.destroy();
		if (dev.isValid()) dev.close();
	}
};

OpenNI2Source::OpenNI2Source(const OpenNI2Params& p)
    : p_(p), d_(std::make_unique<Impl>())
{
	initOpenNI();
	const char* uri = p_.uri.empty() ? openni::ANY_DEVICE : p_.uri.c_str();
	if (d_->dev.open(uri) != openni::STATUS_OK)
		throw std::runtime_error(oniError(
		    p_.uri.empty() ? "no RGB-D device found (plugged in? permissions? "
		                     "device_uri=Dummy gives OpenNI2's test device)"
		                   : "cannot open device '" + p_.uri + "'"));
	if (d_->dev.getPlaybackControl())  // .oni: play once, at recorded speed
		d_->dev.getPlaybackControl()->setRepeatEnabled(false);

	if (!d_->dev.hasSensor(openni::SENSOR_DEPTH) ||
	    d_->depth.create(d_->dev, openni::SENSOR_DEPTH) != openni::STATUS_OK)
		throw std::runtime_error(
		    oniError("device '" + p_.uri + "' has no usable depth stream"));
	chooseMode(d_->depth, p_.width, p_.height, p_.fps, "depth");
	d_->hasColour =
	    d_->dev.hasSensor(openni::SENSOR_COLOR) &&
	    d_->colour.create(d_->dev, openni::SENSOR_COLOR) == openni::STATUS_OK;
	if (d_->hasColour)
		chooseMode(d_->colour, p_.width, p_.height, p_.fps, "colour");
	if (p_.registerDepth && d_->hasColour &&
	    d_->dev.isImageRegistrationModeSupported(
	        openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR))
		d_->dev.setImageRegistrationMode(
		    openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR);
	d_->depth.setMirroringEnabled(false);
	if (d_->hasColour) d_->colour.setMirroringEnabled(false);

	const auto dm = d_->depth.getVideoMode();
	switch (dm.getPixelFormat())
	{
		case openni::PIXEL_FORMAT_DEPTH_1_MM:
			d_->rangeUnits = 0.001;
			break;
		case openni::PIXEL_FORMAT_DEPTH_100_UM:
			d_->rangeUnits = 0.0001;
			break;
		default:
			throw std::runtime_error(
			    "OpenNI2: unsupported depth pixel format " +
			    std::to_string(static_cast<int>(dm.getPixelFormat())));
	}
	if (d_->hasColour && d_->colour.getVideoMode().getPixelFormat() !=
	                         openni::PIXEL_FORMAT_RGB888)
		throw std::runtime_error("OpenNI2: colour stream is not RGB888");
	d_->w = dm.getResolutionX();
	d_->h = dm.getResolutionY();
	double hfov = d_->depth.getHorizontalFieldOfView();
	double vfov = d_->depth.getVerticalFieldOfView();
	if (!(hfov > 0.01 && hfov < 3.1)) hfov = mrpt::DEG2RAD(p_.fallbackHfovDeg);
	d_->fx = d_->w / (2 * std::tan(hfov / 2));
	d_->fy =
	    (vfov > 0.01 && vfov < 3.1) ? d_->h / (2 * std::tan(vfov / 2)) : d_->fx;
	d_->cx = (d_->w - 1) / 2.0;
	d_->cy = (d_->h - 1) / 2.0;

	if (d_->depth.start() != openni::STATUS_OK)
		throw std::runtime_error(oniError("cannot start the depth stream"));
	if (d_->hasColour && d_->colour.start() != openni::STATUS_OK)
		throw std::runtime_error(oniError("cannot start the colour stream"));

	std::ostringstream s;
	const auto info = d_->dev.getDeviceInfo();
	s << (p_.uri.empty() ? std::string(info.getUri()) : p_.uri) << " ("
	  << info.getVendor() << " " << info.getName() << "), depth " << d_->w
	  << "x" << d_->h << "@" << dm.getFps();
	if (d_->hasColour)
	{
		const auto cm = d_->colour.getVideoMode();
		s << " + colour " << cm.getResolutionX() << "x" << cm.getResolutionY();
	}
	s << ", fx=" << d_->fx;
	d_->describe = s.str();
}

OpenNI2Source::~OpenNI2Source()
{
	// OpenNI2's Dummy driver (Debian 2.2.0.33) keeps its frame thread
	// running after stop()/destroy() and then calls into the freed stream
	// (a crash a few ms later). Its streams are therefore left open (a few
	// hundred kB, once per Dummy source) instead of being destroyed. They
	// stay reachable from a static list until exit, so a leak checker sees
	// them kept on purpose, not lost (whether or not the driver's thread
	// has started).
	if (p_.uri == "Dummy")
	{
		static auto* const kept = new std::vector<Impl*>;
		static std::mutex m;
		const std::lock_guard<std::mutex> lock(m);
		kept->push_back(d_.release());
	}
}

std::string OpenNI2Source::describe() const
{
	return d_->describe;
}

mrpt::obs::CObservation3DRangeScan::Ptr OpenNI2Source::grab()
{
	openni::VideoStream* streams[2] = {&d_->depth, &d_->colour};
	const int n = d_->hasColour ? 2 : 1;
	openni::VideoFrameRef depth;
	// A depth frame, with a colour frame received before it (the first
	// depth frames of a colour device are skipped until colour arrives).
	auto ready = [&]
	{ return depth.isValid() && (!d_->hasColour || d_->lastColour.isValid()); };
	for (int guard = 0; guard < 32 && !ready(); ++guard)
	{
		int idx = -1;
		const auto rc =
		    openni::OpenNI::waitForAnyStream(streams, n, &idx, p_.timeoutMs);
		if (rc == openni::STATUS_TIME_OUT) return nullptr;
		if (rc != openni::STATUS_OK)
			throw std::runtime_error(oniError("device lost (unplugged?)"));
		if (idx == 1)
		{
			if (d_->colour.readFrame(&d_->lastColour) != openni::STATUS_OK)
				throw std::runtime_error(oniError("reading colour"));
		}
		else if (d_->depth.readFrame(&depth) != openni::STATUS_OK)
			throw std::runtime_error(oniError("reading depth"));
	}
	if (!ready()) return nullptr;
	const double arrival = hostNow();

	auto o = mrpt::obs::CObservation3DRangeScan::Create();
	o->sensorLabel = p_.sensorLabel;
	o->timestamp = mrpt::Clock::fromDouble(
	    d_->clock.map(depth.getTimestamp() * 1e-6, arrival));
	o->maxRange = static_cast<float>(p_.maxRangeM);
	o->hasRangeImage = true;
	o->range_is_depth = true;
	o->rangeUnits = static_cast<float>(d_->rangeUnits);
	const int w = depth.getWidth(), h = depth.getHeight();
	o->rangeImage_setSize(h, w);
	const auto* src = static_cast<const uint16_t*>(depth.getData());
	const int stride = depth.getStrideInBytes() / 2;
	for (int v = 0; v < h; ++v)
		for (int u = 0; u < w; ++u) o->rangeImage(v, u) = src[v * stride + u];
	o->cameraParams.ncols = static_cast<uint32_t>(w);
	o->cameraParams.nrows = static_cast<uint32_t>(h);
	const double sx = double(w) / d_->w, sy = double(h) / d_->h;
	o->cameraParams.setIntrinsicParamsFromValues(d_->fx * sx, d_->fy * sy,
	                                             d_->cx * sx, d_->cy * sy);
	o->cameraParams.distortion = mrpt::img::DistortionModel::none;
	o->cameraParamsIntensity = o->cameraParams;
	// Registered RGB-D: same optical frame (MRPT's default relative pose).
	o->relativePoseIntensityWRTDepth = mrpt::poses::CPose3D(
	    0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));

	if (d_->lastColour.isValid())
	{
		const auto& c = d_->lastColour;
		const cv::Mat rgb(c.getHeight(), c.getWidth(), CV_8UC3,
		                  const_cast<void*>(c.getData()),
		                  static_cast<size_t>(c.getStrideInBytes()));
		cv::Mat bgr;
		cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
		if (bgr.cols != w || bgr.rows != h)
			cv::resize(bgr, bgr, cv::Size(w, h), 0, 0, cv::INTER_AREA);
		o->hasIntensityImage = true;
		o->intensityImageChannel =
		    mrpt::obs::CObservation3DRangeScan::CH_VISIBLE;
		o->intensityImage = mrpt::img::CImage(bgr, mrpt::img::DEEP_COPY);
	}
	return o;
}

}  // namespace bims::grab
