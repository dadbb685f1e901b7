// The Python module bims._bims (pybind11): the experiment configuration, the
// pipeline on NumPy arrays and the rawlog reader. The package bims
// (libs/python/bims/__init__.py) re-exports it with the Python-side helpers;
// docs/python.md says how to use it.
#ifdef BIMS_PYTHON_IMPORTERS
#include <bims/apps/app.h>
#include <bims/apps/stray_import_run.h>
#include <bims/apps/tum_import_run.h>
#ifdef BIMS_PYTHON_BAG
#include <bims/apps/bag_import_run.h>
#endif
#endif
#include <bims/common/config.h>
#include <bims/common/depth_image.h>
#include <bims/common/imu_check.h>
#include <bims/ego/attitude_filter.h>
#include <bims/ego/flags.h>
#include <bims/ego/rgbd_input.h>
#include <bims/io/image_file.h>
#include <bims/io/rawlog.h>
#include <bims/maps/export.h>
#include <bims/pipeline/config.h>
#include <bims/pipeline/pipeline.h>
#include <bims/source/frame_source.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/system/filesystem.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <opencv2/imgproc.hpp>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace py = pybind11;
using namespace bims;

namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/** Columns of an IMU array: t, gyro xyz, accel xyz, mag xyz, quaternion
 * wxyz (R_WI); the first 7 are required, NaN = the channel is absent. */
constexpr int kImuColumns = 14;
/** The largest frame stamp [s] taken (from 0, 1970): a frame's stamp
 * becomes an mrpt::Clock time, a 64-bit count of 100 ns since 1601 (up to
 * 9.2e11 s), whose conversion back to seconds wraps below 0. */
constexpr double kMaxStamp = 1e11;

/** Raises FileNotFoundError with \a what. */
[[noreturn]] void fileNotFound(const std::string& what)
{
	PyErr_SetString(PyExc_FileNotFoundError, what.c_str());
	throw py::error_already_set();
}

/** A ValueError naming the argument. */
[[noreturn]] void bad(const std::string& arg, const std::string& what)
{
	throw py::value_error(arg + ": " + what);
}

/** \a v as "%g" prints it. */
std::string numText(double v)
{
	char buf[32];
	std::snprintf(buf, sizeof(buf), "%g", v);
	return buf;
}

/** The name of \a h's type, for a TypeError. */
std::string typeName(const py::handle& h)
{
	return py::str(py::type::handle_of(h).attr("__name__"));
}

/** \a h as a double: a Python or NumPy number (not a bool, a string or
 * bytes); else a TypeError naming the argument and what it is. */
double number(const py::handle& h, const std::string& arg,
              const std::string& what)
{
	if (!h.is_none() && !py::isinstance<py::bool_>(h) &&
	    !py::isinstance<py::str>(h) && !py::isinstance<py::bytes>(h) &&
	    PyNumber_Check(h.ptr()))
	{
		PyObject* f = PyNumber_Float(h.ptr());
		if (f)
		{
			const double v = PyFloat_AsDouble(f);
			Py_DECREF(f);
			return v;
		}
		// not convertible (e.g. an array of several values): ours below;
		// what the object's own conversion raised otherwise passes on
		if (!PyErr_ExceptionMatches(PyExc_TypeError) &&
		    !PyErr_ExceptionMatches(PyExc_ValueError))
			throw py::error_already_set();
		PyErr_Clear();
	}
	throw py::type_error(arg + ": " + what + " expected, got " + typeName(h));
}

/** \a h as a file path: a str or an os.PathLike (e.g. pathlib.Path), not
 * empty; else a TypeError (None, a number, ...) or a ValueError naming the
 * argument. The programs take paths the same way: a text, never empty. */
std::string pathArg(const py::handle& h, const std::string& arg)
{
	if (!py::isinstance<py::str>(h) && !py::hasattr(h, "__fspath__"))
		throw py::type_error(
		    arg + ": a path (str or os.PathLike) expected, got " + typeName(h));
	const py::object p = py::module_::import("os").attr("fspath")(h);
	if (!py::isinstance<py::str>(p))
		throw py::type_error(
		    arg + ": a path (str or os.PathLike) expected, got " + typeName(p));
	std::string s = p.cast<std::string>();
	if (s.empty()) bad(arg, "an empty path");
	if (s.find('\0') != std::string::npos)
		bad(arg, "a path with a NUL character");
	return s;
}

/** A C-contiguous array of \a dtype with \a ndim dimensions (else a
 * ValueError or TypeError naming the argument). */
py::array checked(const py::handle& h, const std::string& arg,
                  const py::dtype& dtype, int ndim)
{
	if (!py::isinstance<py::array>(h))
		throw py::type_error(arg + ": a numpy array expected, got " +
		                     std::string(py::str(h.get_type())));
	py::array a = py::reinterpret_borrow<py::array>(h);
	if (!a.dtype().is(dtype))
		throw py::type_error(
		    arg + ": dtype " + std::string(py::str(py::handle(a.dtype()))) +
		    ", " + std::string(py::str(py::handle(dtype))) + " expected");
	if (a.ndim() != ndim)
		bad(arg, std::to_string(a.ndim()) + " dimensions, " +
		             std::to_string(ndim) + " expected");
	if (!(a.flags() & py::array::c_style))
		bad(arg, "not C-contiguous (numpy.ascontiguousarray(...) first)");
	return a;
}

/** A new NumPy array owning a reference to \a m's data (no copy). */
py::array toNumpy(const cv::Mat& m)
{
	if (m.empty()) return py::array_t<uint8_t>(std::vector<py::ssize_t>{0, 0});
	CV_Assert(m.isContinuous() && m.channels() == 1);
	auto* keep = new cv::Mat(m);
	py::capsule owner(keep, [](void* p) { delete static_cast<cv::Mat*>(p); });
	py::dtype dt;
	switch (m.depth())
	{
		case CV_8U:
			dt = py::dtype::of<uint8_t>();
			break;
		case CV_8S:
			dt = py::dtype::of<int8_t>();
			break;
		case CV_16U:
			dt = py::dtype::of<uint16_t>();
			break;
		case CV_32F:
			dt = py::dtype::of<float>();
			break;
		default:
			throw std::logic_error("toNumpy: unexpected image type");
	}
	return py::array(dt, {m.rows, m.cols},
	                 {static_cast<py::ssize_t>(m.step[0]),
	                  static_cast<py::ssize_t>(m.elemSize())},
	                 m.data, owner);
}

/** A rows x cols float64 array of \a M (any matrix with M(r, c)). */
template <class Matrix>
py::array_t<double> toArray(const Matrix& M, int rows, int cols)
{
	py::array_t<double> out({rows, cols});
	auto o = out.mutable_unchecked<2>();
	for (int r = 0; r < rows; ++r)
		for (int c = 0; c < cols; ++c) o(r, c) = M(r, c);
	return out;
}

py::array_t<double> poseMatrix(const mrpt::poses::CPose3D& p)
{
	return toArray(p.getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>(), 4,
	               4);
}

Eigen::Matrix3d intrinsics(const py::handle& h)
{
	py::array_t<double> a =
	    py::array_t<double, py::array::forcecast>::ensure(h);
	if (!a || a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3)
		bad("K", "a 3 x 3 camera matrix expected");
	auto k = a.unchecked<2>();
	Eigen::Matrix3d K;
	for (int r = 0; r < 3; ++r)
		for (int c = 0; c < 3; ++c) K(r, c) = k(r, c);
	if (!(K(0, 0) > 0 && K(1, 1) > 0) || !K.allFinite() || K(2, 2) != 1 ||
	    K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0)
		bad("K",
		    "not a pinhole camera matrix [[fx, 0, cx], [0, fy, cy], [0, 0, "
		    "1]] with finite fx, fy > 0");
	return K;
}

/** Configuration: the programs' strict reader (pipeline::ExperimentConfig). */
struct Config
{
	pipeline::ExperimentConfig cfg;

	static Config fromFile(const std::string& path)
	{
		Config c;
		c.cfg.loadFromFile(path);
		return c;
	}
	static Config fromString(const std::string& text)
	{
		Config c;
		c.cfg.loadFromText(text);
		return c;
	}
	/** KeyError for a key the configuration does not have. */
	static void requireKey(const mrpt::config::CConfigFileMemory& mem,
	                       const std::string& section, const std::string& key)
	{
		if (!mem.keyExists(section, key))
			throw py::key_error(
			    "[" + section + "] " + key +
			    ": no such key (Config.effective() lists them)");
	}
	std::string get(const std::string& section, const std::string& key) const
	{
		mrpt::config::CConfigFileMemory mem(cfg.effectiveIni());
		requireKey(mem, section, key);
		return mem.read_string(section, key, "");
	}
	void set(const std::string& section, const std::string& key,
	         const py::object& value)
	{
		mrpt::config::CConfigFileMemory mem(cfg.effectiveIni());
		requireKey(mem, section, key);
		std::string text = py::isinstance<py::bool_>(value)
		                       ? (value.cast<bool>() ? "true" : "false")
		                       : std::string(py::str(value));
		mem.write(section, key, text);
		std::string content;
		mem.getContent(content);
		pipeline::ExperimentConfig next;
		next.loadFromText(content);  // the same checks as a file's
		next.source = cfg.source;
		cfg = std::move(next);
	}
};

/** The result of one frame, as Python sees it. */
struct Result
{
	size_t index = 0;
	double stamp = 0;
	py::array mask, maskTier1, maskTier2, maskFlow, labels;
	py::array_t<double> pose, motion;
	std::vector<std::string> flags;
	uint32_t flagBits = 0;
	bool warmup = false, flowOff = false;
	py::dict times;
	py::array_t<double> movingVoxels;
	size_t hitVoxels = 0;
};

/** A rows x 3 float64 array of \a pts. */
py::array_t<double> centresArray(const std::vector<mrpt::math::TPoint3D>& pts)
{
	py::array_t<double> v(
	    {static_cast<py::ssize_t>(pts.size()), py::ssize_t(3)});
	auto w = v.mutable_unchecked<2>();
	for (size_t i = 0; i < pts.size(); ++i)
	{
		w(i, 0) = pts[i].x;
		w(i, 1) = pts[i].y;
		w(i, 2) = pts[i].z;
	}
	return v;
}

/** Voxels of a grid: centres and their probabilities. */
struct Voxels
{
	py::array_t<double> centres;
	py::array_t<float> probabilities;
	size_t size() const { return static_cast<size_t>(probabilities.size()); }
};

Voxels voxelsOf(const maps::VoxelSet& v)
{
	py::array_t<float> p(static_cast<py::ssize_t>(v.size()));
	std::copy(v.probabilities.begin(), v.probabilities.end(), p.mutable_data());
	return {centresArray(v.centres), p};
}

/** \a p, or the config's [output] static_p_occupied when None, checked. */
double occupiedThreshold(const py::object& p, double fallback)
{
	const double v = p.is_none()
	                     ? fallback
	                     : number(p, "p_occupied", "a probability in [0, 1)");
	if (!(v >= 0 && v < 1)) bad("p_occupied", "must be in [0, 1)");
	return v;
}

Result resultOf(const pipeline::FrameResult& r, uint32_t moreFlags)
{
	Result o;
	o.index = r.index;
	o.stamp = r.t;
	o.mask = toNumpy(r.mask);
	o.maskTier1 = toNumpy(r.maskTier1);
	o.maskTier2 = toNumpy(r.maskTier2);
	o.maskFlow = toNumpy(r.maskFlow);
	o.labels = toNumpy(r.labels);
	o.pose = poseMatrix(r.T_WC);
	o.motion = poseMatrix(r.T_CprevC);
	o.flagBits = r.ego.flags | moreFlags;
	for (const char* n : ego::flagNames(o.flagBits)) o.flags.emplace_back(n);
	o.warmup = r.warmup;
	o.flowOff = r.flowOff;
	o.times["input"] = r.ms.input;
	o.times["egomotion"] = r.ms.egomotion;
	o.times["flow"] = r.ms.flow;
	o.times["grids"] = r.ms.grids;
	o.times["total"] = r.ms.total;
	o.hitVoxels = r.hitVoxels;
	o.movingVoxels = centresArray(r.movingVoxelCentres);
	return o;
}

/** One call at a time on an object used from several Python threads: a
 * call holds the object's mutex from its start to its end. The GIL is
 * released while a call waits for the mutex (the thread holding it may
 * need the GIL to finish: no deadlock), so the calls of two threads run
 * one after the other, whole, in the order they get the mutex. A call made
 * again from inside a call on the same thread (e.g. by an argument's
 * __float__) would wait for itself: a RuntimeError instead. */
class CallLock
{
 public:
	/** The mutex, held for one call. */
	class Held
	{
	 public:
		explicit Held(CallLock& l) : l_(l) {}
		~Held()
		{
			l_.owner_.store(std::thread::id());
			l_.mu_.unlock();
		}
		Held(const Held&) = delete;
		Held& operator=(const Held&) = delete;

	 private:
		CallLock& l_;
	};

	/** Waits for the other threads' calls on the object \a what. */
	[[nodiscard]] Held hold(const char* what)
	{
		if (owner_.load() == std::this_thread::get_id())
			throw std::runtime_error(
			    std::string(what) +
			    ": called again from inside one of its own calls on the "
			    "same thread (e.g. by an argument's __float__); the first "
			    "call must return first");
		if (!mu_.try_lock())
		{
			py::gil_scoped_release nogil;
			mu_.lock();
		}
		owner_.store(std::this_thread::get_id());
		return Held(*this);
	}

 private:
	std::mutex mu_;
	std::atomic<std::thread::id> owner_{};
};

/** The IMU rows of one process() call, checked before any is used. */
struct ImuRows
{
	std::vector<sensors::ImuSample> used;
	size_t rejected = 0;  ///< rows no IMU measures (imuSampleProblem)
	std::string firstRejected;
	double last = 0;  ///< the last row's time
	bool any = false;
};

/** The pipeline on arrays. Its calls are serialised (CallLock): one
 * pipeline may be used from several threads, one call at a time. */
class PyPipeline
{
 public:
	explicit PyPipeline(const Config& c)
	    : cfg_(c.cfg),
	      pipe_(c.cfg),
	      farthest_(pipeline::farthestDepthUsed(c.cfg))
	{
	}

	Result process(const py::object& depth, const py::object& rgb,
	               const py::object& stamp, const py::object& imu,
	               const py::object& K, const py::object& units)
	{
		const auto held = calls_.hold("bims.Pipeline");
		if (stamp.is_none()) bad("stamp", "required (the frame's time [s])");
		const double t = number(stamp, "stamp", "a time [s] (a number)");
		if (!std::isfinite(t)) bad("stamp", "not finite");
		if (!(t >= 0 && t <= kMaxStamp))
			bad("stamp", numText(t) +
			                 " s is outside the times MRPT's clock holds (0 to "
			                 "1e11 s since 1970)");
		if (haveLast_ && !(t > lastStamp_))
			bad("stamp", std::to_string(t) +
			                 " is not after the previous frame's " +
			                 std::to_string(lastStamp_));
		ego::RgbdFrame frame = decode(depth, rgb, t, K, units);
		const ImuRows rows = imuRows(imu);
		if (rows.rejected > 0)
			warnRejected(rows);  // (may raise: warnings as errors)
		for (const auto& s : rows.used) pipe_.addImu(s);
		if (rows.any)
		{
			lastImu_ = rows.last;
			haveImu_ = true;
		}
		imuRejected_ += rows.rejected;
		const pipeline::FrameResult* r = nullptr;
		{
			py::gil_scoped_release nogil;
			r = &pipe_.processFrame(frame, index_);
		}
		++index_;
		lastStamp_ = t;
		haveLast_ = true;
		return resultOf(*r, rows.rejected ? ego::kFlagImuRejected : 0u);
	}

	size_t framesProcessed()
	{
		const auto held = calls_.hold("bims.Pipeline");
		return pipe_.framesProcessed();
	}
	size_t imuRejected()
	{
		const auto held = calls_.hold("bims.Pipeline");
		return imuRejected_;
	}

	Voxels occupiedVoxels(const py::object& p)
	{
		const auto held = calls_.hold("bims.Pipeline");
		const double th = occupiedThreshold(p, 0.5);
		return voxelsOf(maps::occupiedVoxels(*pipe_.grids().occupancy(), th));
	}
	Voxels movingVoxels()
	{
		const auto held = calls_.hold("bims.Pipeline");
		const auto* m = pipe_.maskGrid();
		return voxelsOf(m ? maps::movingVoxels(*m) : maps::VoxelSet{});
	}
	Voxels staticVoxels(const py::object& p)
	{
		const auto held = calls_.hold("bims.Pipeline");
		const double th = occupiedThreshold(p, cfg_.output.static_p_occupied);
		return voxelsOf(maps::staticVoxels(*pipe_.grids().occupancy(),
		                                   pipe_.maskGrid(), th));
	}
	/** The static map as bims-run writes it: a .ply (centres and
	 * occupancy) or an OctoMap .bt, by the file's extension. */
	size_t saveStaticMap(const py::object& pathObj, const py::object& p)
	{
		const auto held = calls_.hold("bims.Pipeline");
		const std::string path = pathArg(pathObj, "path");
		const double th = occupiedThreshold(p, cfg_.output.static_p_occupied);
		const std::string ext = mrpt::system::extractFileExtension(path);
		const auto& occ = *pipe_.grids().occupancy();
		if (ext == "ply")
			return maps::writeStaticPly(path, occ, pipe_.maskGrid(), th);
		if (ext == "bt")
			return maps::writeStaticOctomap(path, occ, pipe_.maskGrid(), th);
		bad("path", "'" + path + "': .ply or .bt expected");
	}

 private:
	/** The frame's camera model: \a K, the depth array's K, or [camera]. */
	Eigen::Matrix3d cameraOf(const py::object& depth, const py::object& K) const
	{
		if (!K.is_none()) return intrinsics(K);
		const py::object attached = py::getattr(depth, "K", py::none());
		if (!attached.is_none()) return intrinsics(attached);
		const auto& c = cfg_.ego.camera;
		if (!c.given)
			bad("K",
			    "no camera model: pass K=, give the depth as a "
			    "bims.DepthArray with one, or set [camera] in the config");
		Eigen::Matrix3d M;
		M << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1;
		return M;
	}

	/** Metres per reading: \a unitsObj, else the array's units, else
	 * 0.001 (uint16 readings); checked. */
	double readingUnits(const py::object& unitsObj,
	                    const py::object& attached) const
	{
		if (unitsObj.is_none() && attached.is_none()) return 0.001;
		const char* name = unitsObj.is_none() ? "depth.units" : "depth_units";
		const double u = number(unitsObj.is_none() ? attached : unitsObj, name,
		                        "metres per reading (a number)");
		if (!(u > 0) || !std::isfinite(u))
			bad(name, "must be a finite value > 0 [m]");
		return u;
	}

	/** Float depth is in metres: units other than 1 contradict it. */
	static void checkMetres(const py::object& unitsObj,
	                        const py::object& attached)
	{
		for (const auto& [obj, name] : {std::pair{unitsObj, "depth_units"},
		                                std::pair{attached, "depth.units"}})
		{
			if (obj.is_none()) continue;
			const double u = number(obj, name, "metres per reading");
			if (u != 1)
				bad(name, numText(u) +
				              " for float32 depth, which is in metres: units "
				              "apply to uint16 readings (leave it None)");
		}
	}

	/** Float metres \a m (checked: finite, not negative) as 16-bit
	 * readings of \a units: 0.1 mm, or coarser when the farthest reading
	 * needs it (the 16 bits span the frame's range). Readings farther than
	 * any stage reads are no reading (as a depth file's beyond its 16
	 * bits), so that one far value does not coarsen the others' scale. */
	cv::Mat readingsOfMetres(const cv::Mat& m, float& units) const
	{
		cv::Point at;
		if (!cv::checkRange(m, true, &at))
			bad("depth", "non-finite value at row " + std::to_string(at.y) +
			                 ", column " + std::to_string(at.x) +
			                 " (0 marks a pixel without depth)");
		double lo = 0, hi = 0;
		cv::minMaxLoc(m, &lo, &hi);
		if (lo < 0) bad("depth", "negative depth (0 marks no reading)");
		cv::Mat kept = m;
		if (hi > farthest_)
		{
			kept = m.clone();
			kept.setTo(0, m > farthest_);
			cv::minMaxLoc(kept, nullptr, &hi);
		}
		units = static_cast<float>(std::max(1e-4, hi / 65535.0));
		cv::Mat readings;
		kept.convertTo(readings, CV_16UC1, 1.0 / units);
		return readings;
	}

	/** The grey image of \a rgbObj (H x W x 3 RGB or H x W uint8, the
	 * depth's W x H). */
	static cv::Mat greyOf(const py::object& rgbObj, int W, int H)
	{
		if (!py::isinstance<py::array>(rgbObj))
			throw py::type_error("rgb: a numpy array expected, got " +
			                     typeName(rgbObj));
		const py::array ra = py::reinterpret_borrow<py::array>(rgbObj);
		const int nd = static_cast<int>(ra.ndim());
		py::array c =
		    checked(rgbObj, "rgb", py::dtype::of<uint8_t>(), nd == 2 ? 2 : 3);
		if (c.shape(0) != H || c.shape(1) != W)
			bad("rgb",
			    std::to_string(c.shape(1)) + "x" + std::to_string(c.shape(0)) +
			        " differs from the depth's " + std::to_string(W) + "x" +
			        std::to_string(H) + " (registered RGB-D expected)");
		cv::Mat grey;
		if (nd == 2)
			grey = cv::Mat(H, W, CV_8UC1, const_cast<void*>(c.data())).clone();
		else if (c.shape(2) == 3)
			cv::cvtColor(cv::Mat(H, W, CV_8UC3, const_cast<void*>(c.data())),
			             grey, cv::COLOR_RGB2GRAY);
		else
			bad("rgb", "H x W x 3 (RGB) or H x W (grey) expected");
		return grey;
	}

	ego::RgbdFrame decode(const py::object& depthObj, const py::object& rgbObj,
	                      double t, const py::object& K,
	                      const py::object& unitsObj)
	{
		if (!py::isinstance<py::array>(depthObj))
			throw py::type_error("depth: a numpy array expected, got " +
			                     typeName(depthObj));
		const py::array any = py::reinterpret_borrow<py::array>(depthObj);
		DepthImage d;
		cv::Mat quantized;  // float metres -> readings
		const bool isFloat = any.dtype().is(py::dtype::of<float>());
		py::array a = checked(
		    depthObj, "depth",
		    isFloat ? py::dtype::of<float>() : py::dtype::of<uint16_t>(), 2);
		const auto rows = a.shape(0), cols = a.shape(1);
		if (rows == 0 || cols == 0) bad("depth", "empty image");
		// the limits of input image files ([input]), before any copy
		if (const std::string beyond =
		        imageSizeBeyondLimits(static_cast<uint64_t>(rows),
		                              static_cast<uint64_t>(cols), cfg_.input);
		    !beyond.empty())
			bad("depth", beyond);
		const int H = static_cast<int>(rows), W = static_cast<int>(cols);
		if (const std::string small =
		        pipe_.frameSizeProblem(W, H, !rgbObj.is_none());
		    !small.empty())
			bad("depth", small);
		const Eigen::Matrix3d Km = cameraOf(depthObj, K);
		const py::object attachedUnits =
		    py::getattr(depthObj, "units", py::none());
		if (isFloat)
		{
			checkMetres(unitsObj, attachedUnits);
			quantized = readingsOfMetres(
			    cv::Mat(H, W, CV_32FC1, const_cast<void*>(a.data())), d.units);
			d.data = quantized.ptr<uint16_t>(0);
		}
		else
		{
			d.units = static_cast<float>(readingUnits(unitsObj, attachedUnits));
			d.data = static_cast<const uint16_t*>(a.data());
		}
		d.width = W;
		d.height = H;
		d.stride = static_cast<size_t>(W);
		// Euclidean ranges along each pixel's ray (MRPT's range_is_depth =
		// false), when the array says so
		const py::object isDepth =
		    py::getattr(depthObj, "range_is_depth", py::none());
		if (!isDepth.is_none())
		{
			const int truth = PyObject_IsTrue(isDepth.ptr());
			if (truth < 0) throw py::error_already_set();
			d.isDepth = truth == 1;
		}
		d.timestamp = mrpt::Clock::fromDouble(t);
		d.label = "depth";
		const cv::Mat grey =
		    rgbObj.is_none() ? cv::Mat() : greyOf(rgbObj, W, H);
		ego::RgbdFrame f;
		f.t = t;
		const std::string why = ego::rgbdFrameFrom(d, grey, Km, f);
		if (!why.empty()) bad("depth", why);
		return f;
	}

	/** The rows of \a imuObj (None: none), checked: a row with a time not
	 * finite or before the previous row's is a ValueError; a row holding a
	 * value no IMU gives (bims::imuSampleProblem, the rawlog readers' rule:
	 * a field infinite or beyond any sensor's range) is not used,
	 * counted. NaN marks a channel absent. Converted as a rawlog's samples
	 * are (sensors::imuSampleFrom). */
	ImuRows imuRows(const py::object& imuObj) const
	{
		ImuRows out;
		if (imuObj.is_none()) return out;
		py::array a = checked(imuObj, "imu", py::dtype::of<double>(), 2);
		const auto cols = a.shape(1);
		if (cols != 7 && cols != 10 && cols != kImuColumns)
			bad("imu", std::to_string(cols) +
			               " columns: 7 (t, gyro xyz, accel xyz), 10 (and mag "
			               "xyz) or 14 (and the quaternion wxyz) expected");
		auto m = a.unchecked<double, 2>();
		using namespace mrpt::obs;  // the IMU_* data indices
		// the columns of each channel, with MRPT's fields
		struct Channel
		{
			int col;
			std::vector<TIMUDataIndex> fields;
		};
		static const Channel channels[] = {
		    {1, {IMU_WX, IMU_WY, IMU_WZ}},
		    {4, {IMU_X_ACC, IMU_Y_ACC, IMU_Z_ACC}},
		    {7, {IMU_MAG_X, IMU_MAG_Y, IMU_MAG_Z}},
		    {10,
		     {IMU_ORI_QUAT_W, IMU_ORI_QUAT_X, IMU_ORI_QUAT_Y, IMU_ORI_QUAT_Z}}};
		double last = lastImu_;
		bool have = haveImu_;
		for (py::ssize_t i = 0; i < a.shape(0); ++i)
		{
			const double t = m(i, 0);
			if (!std::isfinite(t))
				bad("imu", "row " + std::to_string(i) + ": time not finite");
			if (have && t < last)
				bad("imu", "row " + std::to_string(i) + ": time " +
				               std::to_string(t) +
				               " is before the previous sample's " +
				               std::to_string(last) +
				               " (samples in time order expected)");
			CObservationIMU o;
			for (const Channel& c : channels)
			{
				const int n = static_cast<int>(c.fields.size());
				if (c.col + n > cols) continue;
				bool present = true;  // (NaN: the channel is absent)
				for (int k = 0; k < n; ++k)
					present = present && !std::isnan(m(i, c.col + k));
				if (present)
					for (int k = 0; k < n; ++k)
						o.set(c.fields[k], m(i, c.col + k));
			}
			if (std::string why = imuSampleProblem(o); !why.empty())
			{
				if (out.rejected++ == 0)
					out.firstRejected = "row " + std::to_string(i) + " (t " +
					                    std::to_string(t) + "): " + why;
			}
			else
			{
				sensors::ImuSample s = sensors::imuSampleFrom(o);
				s.t = t;
				out.used.push_back(s);
			}
			last = t;
			have = true;
			out.any = true;
		}
		out.last = last;
		return out;
	}

	/** A RuntimeWarning for the rows not used, as the programs warn. */
	void warnRejected(const ImuRows& rows) const
	{
		const std::string msg =
		    "imu: " + std::to_string(rows.rejected) +
		    " sample(s) not used, holding values no IMU measures (first: " +
		    rows.firstRejected + "); the frame is flagged imu_rejected, " +
		    std::to_string(imuRejected_ + rows.rejected) +
		    " so far (Pipeline.imu_rejected)";
		if (PyErr_WarnEx(PyExc_RuntimeWarning, msg.c_str(), 1) != 0)
			throw py::error_already_set();
	}

	pipeline::ExperimentConfig cfg_;
	pipeline::Pipeline pipe_;
	/** Readings farther [m] are no reading (pipeline::farthestDepthUsed). */
	double farthest_;
	CallLock calls_;
	size_t index_ = 0, imuRejected_ = 0;
	double lastStamp_ = 0, lastImu_ = 0;
	bool haveLast_ = false, haveImu_ = false;
};

/** The IMU samples of a source frame as an N x 14 array. */
py::array_t<double> imuArray(const source::SourceFrame& f)
{
	py::array_t<double> out(
	    {static_cast<py::ssize_t>(f.imu.size()), py::ssize_t(kImuColumns)});
	auto o = out.mutable_unchecked<2>();
	for (size_t i = 0; i < f.imu.size(); ++i)
	{
		const sensors::ImuSample s = sensors::imuSampleFrom(*f.imu[i]);
		double row[kImuColumns];
		std::fill(row, row + kImuColumns, kNaN);
		row[0] = s.t;
		if (s.hasGyro)
			for (int k = 0; k < 3; ++k) row[1 + k] = s.gyro[k];
		if (s.hasAcc)
			for (int k = 0; k < 3; ++k) row[4 + k] = s.acc[k];
		if (s.hasMag)
			for (int k = 0; k < 3; ++k) row[7 + k] = s.mag[k];
		if (s.q_WI)
		{
			row[10] = s.q_WI->w();
			row[11] = s.q_WI->x();
			row[12] = s.q_WI->y();
			row[13] = s.q_WI->z();
		}
		for (int k = 0; k < kImuColumns; ++k) o(i, k) = row[k];
	}
	return out;
}

/** A rawlog's frames, one dict each (the package makes them bims.Frame). */
class PyRawlogReader
{
 public:
	PyRawlogReader(const py::object& pathObj, const Config& c)
	    : path_(pathArg(pathObj, "path")), cfg_(c.cfg)
	{
		if (!mrpt::system::fileExists(path_))
			fileNotFound(path_ + ": no such rawlog");
		checkRawlogPath(path_);  // (a folder, an empty file: RawlogError)
		src_ = std::make_unique<source::RawlogFrameSource>(
		    std::vector<std::string>{path_},
		    source::FrameOrderParams::of(cfg_.ego, cfg_.pipeline.imu_wait_s,
		                                 "bims.read_rawlog"),
		    false);
	}

	py::dict next()
	{
		const auto held = calls_.hold("bims.read_rawlog");
		std::optional<source::SourceFrame> f;
		{
			py::gil_scoped_release nogil;
			f = src_->next();
		}
		if (!f)
		{
			if (!src_->error().empty()) throw std::runtime_error(src_->error());
			// as bims-run: a rawlog without a 3D scan is an error
			if (src_->stats().scansRead == 0)
			{
				const std::string& label = cfg_.ego.sensors.rgbd_label;
				throw RawlogError(
				    path_ + ": no CObservation3DRangeScan (RGB-D) observation" +
				    (label.empty() ? std::string()
				                   : " with label '" + label + "'"));
			}
			throw py::stop_iteration();
		}
		const auto& scan = *f->scan;
		py::dict d;
		d["index"] = f->index;
		d["stamp"] = f->t;
		d["imu"] = imuArray(*f);
		const DepthImage depth = depthImageOf(scan);
		if (depth.empty())
			throw std::runtime_error("3D scan #" + std::to_string(f->index) +
			                         ": no range image");
		py::array_t<uint16_t> z({depth.height, depth.width});
		cv::Mat(depth.height, depth.width, CV_16UC1,
		        const_cast<uint16_t*>(depth.data),
		        depth.stride * sizeof(uint16_t))
		    .copyTo(
		        cv::Mat(depth.height, depth.width, CV_16UC1, z.mutable_data()));
		d["depth"] = z;
		d["depth_units"] = double(depth.units);
		d["range_is_depth"] = depth.isDepth;
		Eigen::Matrix3d K;
		const std::string why = sensors::intrinsicsOf(scan, cfg_.ego.camera, K);
		if (!why.empty())
			throw std::runtime_error("3D scan #" + std::to_string(f->index) +
			                         ": " + why);
		d["K"] = toArray(K, 3, 3);
		d["rgb"] = py::none();
		if (scan.hasIntensityImage && !scan.intensityImage.isEmpty())
		{
			const cv::Mat img =
			    scan.intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY);
			py::array_t<uint8_t> a({img.rows, img.cols, 3});
			cv::Mat rgb(img.rows, img.cols, CV_8UC3, a.mutable_data());
			cv::cvtColor(
			    img, rgb,
			    img.channels() == 3 ? cv::COLOR_BGR2RGB : cv::COLOR_GRAY2RGB);
			d["rgb"] = a;
		}
		return d;
	}

 private:
	std::string path_;
	pipeline::ExperimentConfig cfg_;
	std::unique_ptr<source::RawlogFrameSource> src_;
	CallLock calls_;
};

#ifdef BIMS_PYTHON_IMPORTERS
/** \a cb (a Python callable(done, total), or None) as a library's progress
 * callback: called with the GIL held, at each report. */
ProgressCallback progressOf(const py::object& cb)
{
	if (cb.is_none()) return {};
	if (!PyCallable_Check(cb.ptr()))
		throw py::type_error("progress: a callable(done, total) expected");
	return [cb](const Progress& p)
	{
		py::gil_scoped_acquire gil;
		cb(p.done, p.total);
	};
}

/** \a path (pathArg), or nullopt for None. */
std::optional<std::string> optionalPath(const py::object& path,
                                        const std::string& arg)
{
	if (path.is_none()) return std::nullopt;
	return pathArg(path, arg);
}

/** The options every importer's run shares (apps/import_options.h). */
template <class Options>
Options importOptions(const py::object& out, const py::object& config,
                      size_t maxFrames, int gz)
{
	Options o;
	o.out = pathArg(out, "out");
	o.config = optionalPath(config, "config");
	o.max_frames = maxFrames;
	o.gz = gz;
	return o;
}

/** \a run with the GIL released (the import's own threads and progress
 * callback take it when they need it). */
template <class Run>
auto withoutGil(const Run& run)
{
	py::gil_scoped_release nogil;
	return run();
}

py::dict importTum(const py::object& folder, const py::object& out,
                   const py::object& config, size_t maxFrames, int gz,
                   bool bonnGt, bool synthImu, uint64_t seed,
                   const py::object& progress)
{
	auto o = importOptions<apps::ImportRunOptions>(out, config, maxFrames, gz);
	o.folder = pathArg(folder, "folder");
	o.bonn_gt = bonnGt;
	o.synth_imu = synthImu;
	o.seed = seed;
	const auto cb = progressOf(progress);
	const apps::TumImport r =
	    withoutGil([&] { return apps::importTumChecked(o, cb); });
	const auto& s = r.summary;
	py::dict d;
	d["frames"] = s.frames;
	d["imu"] = s.imu;
	d["accel"] = s.accel;
	d["gt_poses"] = s.gtPoses;
	d["frames_without_gt"] = s.framesWithoutGt;
	d["gt_dir"] = s.gtDir;
	d["report"] =
	    apps::importReport(o.out, s, o.synth_imu, r.bonnConverted, r.params);
	return d;
}

py::dict importStray(const py::object& folder, const py::object& out,
                     const py::object& config, size_t maxFrames, int gz,
                     const py::object& progress)
{
	auto o =
	    importOptions<apps::StrayImportRunOptions>(out, config, maxFrames, gz);
	o.folder = pathArg(folder, "folder");
	const auto cb = progressOf(progress);
	const auto s = withoutGil([&] { return apps::importStrayChecked(o, cb); });
	py::dict d;
	d["frames"] = s.frames;
	d["imu"] = s.imu;
	d["width"] = s.width;
	d["height"] = s.height;
	d["colour"] = s.colour;
	d["reference"] = s.referencePath;
	d["reference_poses"] = s.referencePoses;
	d["report"] = apps::strayImportReport(o.out, s);
	return d;
}

#ifdef BIMS_PYTHON_BAG
py::dict importBag(const py::object& bags, const py::object& out,
                   const py::object& config, const py::object& layout,
                   size_t maxFrames, int gz, const py::object& progress)
{
	auto o =
	    importOptions<apps::BagImportRunOptions>(out, config, maxFrames, gz);
	if (py::isinstance<py::str>(bags) || py::hasattr(bags, "__fspath__") ||
	    !py::isinstance<py::iterable>(bags))
		o.bags.push_back(pathArg(bags, "bags"));
	else
		for (const auto& b : bags) o.bags.push_back(pathArg(b, "bags"));
	if (o.bags.empty()) bad("bags", "no bag given");
	o.layout = optionalPath(layout, "layout");
	const auto cb = progressOf(progress);
	const apps::BagImport r =
	    withoutGil([&] { return apps::importBagChecked(o, cb); });
	py::dict d;
	d["frames"] = r.summary.frames;
	d["imu"] = r.summary.imu;
	d["width"] = r.summary.width;
	d["height"] = r.summary.height;
	d["report"] = apps::bagImportReport(o.out, r.summary, r.params);
	return d;
}
#endif
#endif

}  // namespace

namespace
{
/** bims.import_tum, import_stray, import_bag: the programs' imports. */
void defineImporters([[maybe_unused]] py::module_& m)
{
#ifdef BIMS_PYTHON_IMPORTERS
	// the programs' usage errors (options that do not fit)
	py::register_exception<UsageError>(m, "UsageError", PyExc_ValueError);

	m.def("import_tum", &importTum, py::arg("folder"), py::arg("out"),
	      py::arg("config") = py::none(), py::arg("max_frames") = 0,
	      py::arg("gz_level") = 1, py::arg("bonn_gt") = false,
	      py::arg("synth_imu") = false, py::arg("seed") = 1,
	      py::arg("progress") = py::none(),
	      "A TUM RGB-D folder into an MRPT rawlog, as bims-import-tum "
	      "(OUT_gt/groundtruth.txt beside it); returns its summary, with "
	      "'report' the lines the program prints");
	m.def("import_stray", &importStray, py::arg("folder"), py::arg("out"),
	      py::arg("config") = py::none(), py::arg("max_frames") = 0,
	      py::arg("gz_level") = 1, py::arg("progress") = py::none(),
	      "A Stray Scanner capture (LiDAR depth, IMU, ARKit poses) into an "
	      "MRPT rawlog, as bims-import-stray; returns its summary");
#ifdef BIMS_PYTHON_BAG
	m.def("import_bag", &importBag, py::arg("bags"), py::arg("out"),
	      py::arg("config") = py::none(), py::arg("layout") = py::none(),
	      py::arg("max_frames") = 0, py::arg("gz_level") = 1,
	      py::arg("progress") = py::none(),
	      "ROS 1 or ROS 2 bags (one path or a list, read as one recording: "
	      ".bag files, ROS 2 bag folders, .mcap or .db3 files) into an MRPT "
	      "rawlog, as bims-import-bag; returns its summary");
#endif
#endif
}

/** bims.Config. */
void defineConfig(py::module_& m)
{
	py::class_<Config>(m, "Config", "An experiment configuration (.ini)")
	    .def(py::init<>(), "The built-in defaults (config/default.ini's)")
	    .def_static(
	        "from_file",
	        [](const py::object& path)
	        {
		        try
		        {
			        return Config::fromFile(pathArg(path, "path"));
		        }
		        catch (const ConfigFileMissing& e)
		        {
			        fileNotFound(e.what());
		        }
	        },
	        py::arg("path"),
	        "Reads an .ini file (or a preset name such as 'bonn.ini') with the "
	        "programs' checks")
	    .def_static("from_string", &Config::fromString, py::arg("text"),
	                "Reads .ini text with the programs' checks")
	    .def("get", &Config::get, py::arg("section"), py::arg("key"),
	         "The value in use of [section] key, as text")
	    .def("set", &Config::set, py::arg("section"), py::arg("key"),
	         py::arg("value"),
	         "Sets [section] key (checked as a file's value would be)")
	    .def(
	        "effective", [](const Config& c) { return c.cfg.effectiveIni(); },
	        "Every section and key with the value in use (effective.ini)")
	    .def_property_readonly("source",
	                           [](const Config& c) { return c.cfg.source; });
}

/** bims.Result and bims.Voxels: what a frame produced. */
void defineResults(py::module_& m)
{
	py::class_<Result>(m, "Result", "What one frame produced")
	    .def_readonly("index", &Result::index)
	    .def_readonly("stamp", &Result::stamp)
	    .def_readonly("mask", &Result::mask,
	                  "H x W uint8, 255 = moving (bims-run's masks/)")
	    .def_readonly("mask_tier1", &Result::maskTier1)
	    .def_readonly("mask_tier2", &Result::maskTier2)
	    .def_readonly("mask_flow", &Result::maskFlow)
	    .def_readonly("labels", &Result::labels,
	                  "H x W int8 flow labels: -1 none, 0 notDiff, 1 Diff")
	    .def_readonly("pose", &Result::pose, "4 x 4 float64, T_WC")
	    .def_readonly(
	        "motion", &Result::motion,
	        "4 x 4 float64, T_CprevC (relative to the previous frame)")
	    .def_readonly("flags", &Result::flags, "the egomotion flags' names")
	    .def_readonly("flag_bits", &Result::flagBits)
	    .def_readonly("warmup", &Result::warmup)
	    .def_readonly("flow_off", &Result::flowOff)
	    .def_readonly("times", &Result::times, "per-stage wall time [ms]")
	    .def_readonly("moving_voxels", &Result::movingVoxels,
	                  "N x 3 centres [m] of the voxels labelled moving")
	    .def_readonly("hit_voxels", &Result::hitVoxels);

	py::class_<Voxels>(m, "Voxels", "Voxels of a grid with a probability each")
	    .def_readonly("centres", &Voxels::centres, "N x 3 float64 [m], {W}")
	    .def_readonly("probabilities", &Voxels::probabilities,
	                  "N float32: occupancy (tier 0) or P(moving)")
	    .def("__len__", &Voxels::size)
	    .def("__repr__", [](const Voxels& v)
	         { return "<bims.Voxels: " + std::to_string(v.size()) + ">"; });
}

/** bims.Pipeline and the rawlog reader. */
void definePipeline(py::module_& m)
{
	py::class_<PyPipeline>(
	    m, "Pipeline",
	    "The segmentation pipeline. Its calls are serialised: from several "
	    "threads they run one at a time, whole")
	    .def(py::init<const Config&>(), py::arg("config"))
	    .def(
	        "process", &PyPipeline::process, py::arg("depth"),
	        py::arg("rgb") = py::none(), py::arg("stamp") = py::none(),
	        py::arg("imu") = py::none(), py::arg("K") = py::none(),
	        py::arg("depth_units") = py::none(),
	        "Runs one frame: depth H x W uint16 (x depth_units [m], default "
	        "the array's units or 0.001) or float32 [m]; rgb H x W x 3 uint8 "
	        "(RGB) or H x W; stamp [s]; imu N x 7/10/14 float64 rows (t, gyro, "
	        "accel[, mag[, quaternion wxyz]]) up to this frame")
	    .def_property_readonly("frames_processed", &PyPipeline::framesProcessed)
	    .def_property_readonly(
	        "imu_rejected", &PyPipeline::imuRejected,
	        "IMU rows not used: values no IMU measures (a warning each call)")
	    .def("occupied_voxels", &PyPipeline::occupiedVoxels,
	         py::arg("p_occupied") = 0.5,
	         "Tier 0's voxels with occupancy probability > p_occupied")
	    .def("moving_voxels", &PyPipeline::movingVoxels,
	         "The last frame's voxels the variant's tier labels moving, with "
	         "their P(moving) (empty for flow-only)")
	    .def("static_voxels", &PyPipeline::staticVoxels,
	         py::arg("p_occupied") = py::none(),
	         "The static map: occupied voxels (p > p_occupied, default "
	         "[output] static_p_occupied) not labelled moving at their last "
	         "hit")
	    .def("save_static_map", &PyPipeline::saveStaticMap, py::arg("path"),
	         py::arg("p_occupied") = py::none(),
	         "Writes the static map as bims-run does: PATH.ply (binary, x y z "
	         "value) or PATH.bt (OctoMap); returns the number of voxels");

	py::class_<PyRawlogReader>(m, "_RawlogReader")
	    .def(py::init<const py::object&, const Config&>())
	    .def("__iter__", [](PyRawlogReader& r) -> PyRawlogReader& { return r; })
	    .def("__next__", &PyRawlogReader::next);
}
}  // namespace

PYBIND11_MODULE(_bims, m)
{
	m.doc() = "bims: Bayesian independent motion segmentation (C++ core)";
	py::register_exception<ConfigError>(m, "ConfigError", PyExc_ValueError);
	py::register_exception<RawlogError>(m, "RawlogError", PyExc_OSError);
	defineImporters(m);
	defineConfig(m);
	defineResults(m);
	definePipeline(m);
}
