#include <bims/common/progress.h>
#include <bims/eval/rgbd_frame.h>
#include <bims/eval/stray_import.h>
#include <bims/eval/tum_import.h>
#include <bims/io/image_file.h>
#include <bims/io/output_paths.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/sensors/camera.h>

#include "import_rawlog.h"

#include <mrpt/core/Clock.h>
#include <mrpt/obs/CObservationIMU.h>

#include <mrpt/core/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <stdexcept>

namespace bims::eval
{
namespace
{
std::string sizeText(int w, int h)
{
	return std::to_string(w) + "x" + std::to_string(h);
}

/** The number of frames of an opened video: the container's count, or
 * the frames decoded when it gives none (the video is reopened). */
size_t videoFrameCount(cv::VideoCapture& video, const std::string& path)
{
	const double n = video.get(cv::CAP_PROP_FRAME_COUNT);
	if (n > 0) return static_cast<size_t>(std::llround(n));
	size_t count = 0;
	while (video.grab()) count++;
	video.release();
	if (!video.open(path))
		throw std::runtime_error(path + ": cannot open the video again");
	return count;
}

/** The IMU sample as the rawlog's observation: specific force -a (Apple's
 * accelerometer points down at rest; a specific force points up), the
 * gyro as is; no magnetometer, no orientation. */
mrpt::obs::CObservationIMU::Ptr strayImuObservation(const StrayImuSample& s,
                                                    const std::string& label)
{
	const double f[3] = {-s.a[0], -s.a[1], -s.a[2]};
	return imuObservation(label, s.t, s.alpha, f, nullptr);
}

/** The depth grid of the import: the size of its first depth image. */
void readDepthGrid(const std::string& firstDepth,
                   const StrayImportParams& params, StrayImportSummary& sum)
{
	const cv::Mat d = readDepthPng(firstDepth, params.images);
	sum.width = d.cols;
	sum.height = d.rows;
}

/** Opens rgb.mp4 and checks it against the capture: frame k of the video
 * is the k-th depth frame (all of them: the count is checked before
 * --max-frames), of the depth images' aspect ratio. */
void openStrayVideo(const StrayCapture& cap, const std::string& firstDepth,
                    cv::VideoCapture& video, StrayImportSummary& sum)
{
	const std::string& vp = cap.videoPath;
	if (!video.open(vp))
		throw std::runtime_error(
		    vp + ": cannot open the video (OpenCV's video I/O)");
	sum.colour = true;
	sum.videoWidth = static_cast<int>(video.get(cv::CAP_PROP_FRAME_WIDTH));
	sum.videoHeight = static_cast<int>(video.get(cv::CAP_PROP_FRAME_HEIGHT));
	const size_t n = videoFrameCount(video, vp);
	if (n != cap.frames.size())
		throw std::runtime_error(
		    vp + ": " + std::to_string(n) +
		    " video frames, but the capture has " +
		    std::to_string(cap.frames.size()) +
		    " depth frames (odometry.csv); video frame k must be depth "
		    "frame k");
	for (size_t k = 0; k < cap.frames.size(); k++)
		if (cap.frames[k].index != static_cast<long>(k))
			throw std::runtime_error(
			    cap.path +
			    "/odometry.csv:" + std::to_string(cap.frames[k].line) +
			    ": frame " + std::to_string(cap.frames[k].index) + " is row " +
			    std::to_string(k + 1) +
			    ": with rgb.mp4 the frames must be 0, 1, 2, ... (video "
			    "frame k is depth frame k)");
	// the same field of view: the aspect ratios agree (to 1 %)
	const double a = double(sum.videoWidth) * sum.height,
	             b = double(sum.videoHeight) * sum.width;
	if (!(sum.videoWidth > 0 && sum.videoHeight > 0) ||
	    std::abs(a - b) > 0.01 * std::max(a, b))
		throw std::runtime_error(vp + ": video frames are " +
		                         sizeText(sum.videoWidth, sum.videoHeight) +
		                         ", not of the depth images' aspect ratio (" +
		                         sizeText(sum.width, sum.height) + ", " +
		                         firstDepth + ")");
}

/** The colour image size camera_matrix.csv was made for, with a video: its
 * principal point near the centre of the video's frames, or else of the
 * [import_stray] colour size (a re-encoded video: the same view, scaled;
 * said in a note). */
void strayVideoColourSize(const StrayCapture& cap,
                          const StrayImportParams& params,
                          StrayImportSummary& sum, int& colourW, int& colourH)
{
	const std::string& vp = cap.videoPath;
	const double cx = cap.K[0][2], cy = cap.K[1][2];
	const auto central = [&](int w, int h)
	{
		return w > 0 && h > 0 &&
		       std::abs(cx / w - 0.5) <= kStrayCentreTolerance &&
		       std::abs(cy / h - 0.5) <= kStrayCentreTolerance;
	};
	const double va = double(sum.videoWidth) * params.colour_height,
	             vb = double(sum.videoHeight) * params.colour_width;
	if (central(sum.videoWidth, sum.videoHeight))
	{
		colourW = sum.videoWidth;
		colourH = sum.videoHeight;
	}
	else if (central(params.colour_width, params.colour_height) &&
	         std::abs(va - vb) <= 0.01 * std::max(va, vb))
		sum.notes.push_back(
		    vp + ": frames of " + sizeText(sum.videoWidth, sum.videoHeight) +
		    ", " + cap.path + "/camera_matrix.csv of the " +
		    sizeText(params.colour_width, params.colour_height) +
		    " colour stream ([import_stray] colour_width, colour_height): "
		    "the video is taken as that view scaled");
	else
		throw std::runtime_error(mrpt::format(
		    "%s: frames of %s, but the principal point of %s/"
		    "camera_matrix.csv (cx %g, cy %g) is not near their centre "
		    "(within %g of the size) nor that of the %s colour stream of "
		    "[import_stray] colour_width, colour_height with the video's "
		    "aspect ratio: the matrix is of another image size (give the "
		    "size it was made for as colour_width, colour_height)",
		    vp.c_str(), sizeText(sum.videoWidth, sum.videoHeight).c_str(),
		    cap.path.c_str(), cx, cy, kStrayCentreTolerance,
		    sizeText(params.colour_width, params.colour_height).c_str()));
}

/** Which frames are written: the rawlog's clock ticks in 100 ns, a frame on
 * the tick of the one before would be dropped by every reader; it is left
 * out here and counted. */
std::vector<bool> framesOnTicksOfTheirOwn(const std::vector<StrayFrame>& frames,
                                          StrayImportSummary& sum)
{
	std::vector<bool> written(frames.size(), true);
	for (size_t i = 1, last = 0; i < frames.size(); i++)
		if (mrpt::Clock::fromDouble(frames[i].t) ==
		    mrpt::Clock::fromDouble(frames[last].t))
		{
			written[i] = false;
			sum.framesSameStamp++;
		}
		else
			last = i;
	return written;
}

/** The IMU samples to write, kind 0 (from the start of the file: the
 * attitude filter wants those before the first frame; up to \a t1, the
 * last frame written), counted in \a sum; returns how many are within the
 * frames' span from \a t0. */
size_t strayImuInputs(const StrayCapture& cap, double t0, double t1,
                      std::vector<TimedInput>& items, StrayImportSummary& sum)
{
	const double tEnd = cap.frames.back().t;  // of the whole capture
	size_t inSpan = 0;
	for (size_t i = 0, last = 0; i < cap.imu.size(); i++)
	{
		const double t = cap.imu[i].t;
		if (t > tEnd) sum.imuAfterLast++;
		if (t > t1) continue;
		if (!items.empty() && mrpt::Clock::fromDouble(t) ==
		                          mrpt::Clock::fromDouble(cap.imu[last].t))
		{
			sum.imuSameStamp++;
			continue;
		}
		last = i;
		items.push_back({t, 0, i});
		sum.imuBeforeFirst += t < t0;
		inSpan += t >= t0;
	}
	return inSpan;
}

/** The warnings of the IMU and frames left out (imu.csv on another clock,
 * samples or frames on one tick). */
void strayTimeWarnings(const StrayCapture& cap, size_t inSpan, double t0,
                       double t1, StrayImportSummary& sum)
{
	const std::string imuCsv = cap.path + "/imu.csv";
	const double tEnd = cap.frames.back().t;
	if (sum.imuAfterLast > 0)
		sum.warnings.push_back(mrpt::format(
		    "%s: %zu of its %zu samples are after the capture's last frame "
		    "(t %.6f s) and were left out: is the IMU on odometry.csv's clock "
		    "and in seconds?",
		    imuCsv.c_str(), sum.imuAfterLast, cap.imu.size(), tEnd));
	if (!cap.imu.empty() && inSpan == 0)
		sum.warnings.push_back(mrpt::format(
		    "%s: none of its %zu samples (t %.6f to %.6f s) is within the "
		    "frames' time span (%.6f to %.6f s): another clock or other "
		    "units? The frames get no IMU",
		    imuCsv.c_str(), cap.imu.size(), cap.imu.front().t, cap.imu.back().t,
		    t0, t1));
	if (sum.imuSameStamp > 0)
		sum.warnings.push_back(mrpt::format(
		    "%s: %zu samples left out: each on the 100 ns tick of the sample "
		    "before (the rawlog's clock)",
		    imuCsv.c_str(), sum.imuSameStamp));
	if (sum.framesSameStamp > 0)
		sum.warnings.push_back(mrpt::format(
		    "%s/odometry.csv: %zu frames left out: each within the 100 ns "
		    "tick of the frame before (the rawlog's clock: two scans of one "
		    "stamp are one too many for every reader)",
		    cap.path.c_str(), sum.framesSameStamp));
}

/** Frames (kind 1) and IMU (kind 0) in time order, the IMU first at equal
 * stamps; what is left out is counted and warned of in \a sum. */
std::vector<TimedInput> strayTimeOrder(const StrayCapture& cap,
                                       const std::vector<StrayFrame>& frames,
                                       StrayImportSummary& sum)
{
	const double t0 = frames.front().t, t1 = frames.back().t;
	std::vector<TimedInput> items;
	const size_t inSpan = strayImuInputs(cap, t0, t1, items, sum);
	strayTimeWarnings(cap, inSpan, t0, t1, sum);
	for (size_t i = 0; i < frames.size(); i++)
		items.push_back({frames[i].t, 1, i});
	sortByTime(items);
	return items;
}

/** The depth image of \a f with the readings below [import_stray]
 * min_confidence made 0 (when the capture has confidence images),
 * counted in \a sum. */
cv::Mat confidentDepth(const StrayFrame& f, const StrayCapture& cap,
                       const StrayImportParams& params,
                       const std::string& firstDepth, StrayImportSummary& sum)
{
	cv::Mat depth = readDepthPng(f.depthPath, params.images);
	if (depth.cols != sum.width || depth.rows != sum.height)
		throw std::runtime_error(f.depthPath + ": depth image is " +
		                         sizeText(depth.cols, depth.rows) +
		                         " but the first (" + firstDepth + ") is " +
		                         sizeText(sum.width, sum.height));
	cv::Mat conf;
	if (cap.hasConfidence)
	{
		conf = readImageFile(f.confidencePath, cv::IMREAD_UNCHANGED,
		                     "confidence image", params.images);
		if (conf.type() != CV_8UC1)
			throw std::runtime_error(
			    f.confidencePath +
			    ": confidence must be an 8-bit single-channel PNG");
		if (conf.cols != sum.width || conf.rows != sum.height)
			throw std::runtime_error(
			    f.confidencePath + ": confidence image is " +
			    sizeText(conf.cols, conf.rows) + " but its depth image (" +
			    f.depthPath + ") is " + sizeText(sum.width, sum.height));
	}
	for (int v = 0; v < depth.rows; v++)
	{
		uint16_t* d = depth.ptr<uint16_t>(v);
		const uint8_t* c = conf.empty() ? nullptr : conf.ptr<uint8_t>(v);
		for (int u = 0; u < depth.cols; u++)
		{
			if (d[u] == 0) continue;
			sum.readings++;
			if (c && c[u] < params.min_confidence)
			{
				d[u] = 0;
				sum.dropped++;
			}
		}
	}
	return depth;
}

std::runtime_error videoEndsEarly(const StrayCapture& cap, size_t i)
{
	return std::runtime_error(
	    cap.videoPath + ": ends after " + std::to_string(i) +
	    " frames, but the capture has " + std::to_string(cap.frames.size()) +
	    " depth frames");
}

/** Video frame \a i (the next one) down to the depth grid, attached to
 * \a o: ARKit registers the depth to this camera, so the grid stays
 * registered RGB-D at the LiDAR's own resolution. \a bgr, \a small:
 * buffers reused across frames. */
void attachVideoFrame(cv::VideoCapture& video, const StrayCapture& cap,
                      size_t i, const StrayImportSummary& sum, cv::Mat& bgr,
                      cv::Mat& small, mrpt::obs::CObservation3DRangeScan& o)
{
	if (!video.read(bgr) || bgr.empty()) throw videoEndsEarly(cap, i);
	if (bgr.cols != sum.videoWidth || bgr.rows != sum.videoHeight ||
	    bgr.type() != CV_8UC3)
		throw std::runtime_error(cap.videoPath + ": frame " +
		                         std::to_string(i) + " is " +
		                         sizeText(bgr.cols, bgr.rows) + ", the first " +
		                         sizeText(sum.videoWidth, sum.videoHeight));
	cv::resize(bgr, small, cv::Size(sum.width, sum.height), 0, 0,
	           cv::INTER_AREA);
	attachColour(o, small);
}

/** ARKit's poses at the written frames, from the first with a position
 * (before it, translation exactly 0: ARKit initialising). */
void strayReference(const std::vector<StrayFrame>& frames,
                    const std::vector<bool>& written, StrayImportSummary& sum)
{
	size_t k = 0;
	while (k < frames.size() && frames[k].p[0] == 0 && frames[k].p[1] == 0 &&
	       frames[k].p[2] == 0)
		k++;
	for (size_t j = 0; j < k; j++) sum.referenceLeftOut += written[j];
	for (; k < frames.size(); k++)
		if (written[k])
			sum.reference.push_back({frames[k].t, frames[k].pose()});
	sum.referencePoses = sum.reference.size();
}

/** The reference's file text (TUM format, with its header). */
std::string strayReferenceText(const std::string& folder,
                               const StrayImportSummary& sum)
{
	return tumTrajectoryText(
	    sum.referencePath, sum.reference,
	    "ARKit's visual-inertial estimate, NOT ground truth: a reference. "
	    "T_WC of the camera optical frame (x right, y down, z forward) in "
	    "ARKit's world (y up) at each 3D scan's stamp, from " +
	        folder + "/odometry.csv; the first " +
	        std::to_string(sum.referenceLeftOut) +
	        " frames (translation exactly 0: ARKit initialising) left out");
}
}  // namespace

std::string strayReferencePathFor(const std::string& rawlogPath)
{
	// groundTruthDirFor's "OUT_gt" without its suffix: OUT
	std::string base = groundTruthDirFor(rawlogPath);
	base.resize(base.size() - 3);
	return base + "_arkit_reference.txt";
}

StrayImportSummary importStray(const std::string& folder,
                               const std::string& outRawlog,
                               const StrayImportParams& params,
                               const StrayImportOptions& options)
{
	return importStray(readStrayCapture(folder, options.warn), outRawlog,
	                   params, options);
}

std::vector<std::string> strayInputFiles(const StrayCapture& cap)
{
	std::vector<std::string> files;
	for (const char* name : {"odometry.csv", "imu.csv", "camera_matrix.csv"})
		files.push_back(cap.path + "/" + name);
	files.push_back(cap.videoPath);
	for (const auto& f : cap.frames)
	{
		files.push_back(f.depthPath);
		files.push_back(f.confidencePath);
	}
	return files;
}

StrayImportSummary importStray(const StrayCapture& cap,
                               const std::string& outRawlog,
                               const StrayImportParams& params,
                               const StrayImportOptions& options)
{
	const std::string& folder = cap.path;
	std::vector<StrayFrame> frames = cap.frames;
	if (options.maxFrames > 0 && frames.size() > options.maxFrames)
		frames.resize(options.maxFrames);

	StrayImportSummary sum;
	sum.confidence = cap.hasConfidence;
	sum.minConfidence = params.min_confidence;
	// the depth grid: the first image's size, every image's
	const std::string firstDepth = frames.front().depthPath;
	readDepthGrid(firstDepth, params, sum);
	cv::VideoCapture video;
	int colourW = params.colour_width, colourH = params.colour_height;
	if (!cap.videoPath.empty())
	{
		openStrayVideo(cap, firstDepth, video, sum);
		strayVideoColourSize(cap, params, sum, colourW, colourH);
	}
	sum.camera =
	    strayDepthCamera(cap.K, colourW, colourH, sum.width, sum.height);
	sensors::checkIntrinsics(
	    sensors::PinholeCamera::of(sum.camera),
	    folder + "/camera_matrix.csv (of a " + sizeText(colourW, colourH) +
	        " colour image, scaled to the " + sizeText(sum.width, sum.height) +
	        " depth grid)");

	const std::vector<bool> written = framesOnTicksOfTheirOwn(frames, sum);
	const std::vector<TimedInput> items = strayTimeOrder(cap, frames, sum);
	ImportRawlog out(outRawlog, options.gzLevel,
	                 frames.size() - sum.framesSameStamp, options.progress);
	cv::Mat bgr, small;
	for (const auto& it : items)
	{
		if (it.kind == 0)
		{
			out.w.write(*strayImuObservation(cap.imu[it.i], params.imu_label));
			sum.imu++;
			continue;
		}
		if (!written[it.i])
		{
			// its video frame is skipped with it
			if (sum.colour && !video.grab()) throw videoEndsEarly(cap, it.i);
			continue;
		}
		const StrayFrame& f = frames[it.i];
		auto o = depthObservation(
		    confidentDepth(f, cap, params, firstDepth, sum), kStrayRangeUnits,
		    sum.camera, params.rgbd_label, f.t, kStrayRangeUnits);
		if (sum.colour) attachVideoFrame(video, cap, it.i, sum, bgr, small, *o);
		out.w.write(*o);
		out.frameWritten(++sum.frames);
	}
	// all of the video read: nothing may be left (a container that
	// counted its frames wrong)
	if (sum.colour && frames.size() == cap.frames.size() && video.grab())
		throw std::runtime_error(
		    cap.videoPath + ": more than " + std::to_string(cap.frames.size()) +
		    " video frames, but the capture has " +
		    std::to_string(cap.frames.size()) + " depth frames");
	out.w.close();

	sum.referencePath = strayReferencePathFor(outRawlog);
	strayReference(frames, written, sum);
	// the rawlog and its reference put in place together (another run
	// writing the same OUT at once: one run's pair wins whole)
	PartialFile ref(sum.referencePath);
	writePartialFile(ref, strayReferenceText(folder, sum));
	commitTogether({&out.part, &ref});
	out.finished();
	return sum;
}

}  // namespace bims::eval
