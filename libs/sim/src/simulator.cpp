#include <bims/common/progress.h>
#include <bims/io/frame_files.h>
#include <bims/io/output_paths.h>
#include <bims/io/pixel_labels.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/sim/simulator.h>
#include <mrpt/math/CMatrixFixed.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/TPixelLabelInfo.h>
#include <mrpt/poses/CPose3D.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <sstream>
#include <stdexcept>

namespace bims::sim
{
namespace
{
mrpt::poses::CPose3D toPose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t)
{
	mrpt::math::CMatrixDouble44 M = mrpt::math::CMatrixDouble44::Identity();
	for (int r = 0; r < 3; r++)
	{
		for (int c = 0; c < 3; c++) M(r, c) = R(r, c);
		M(r, 3) = t[r];
	}
	return mrpt::poses::CPose3D(M);
}

mrpt::obs::CObservation3DRangeScan::Ptr makeScan(const SimConfig& cfg,
                                                 RenderedFrame& f, double stamp)
{
	using mrpt::obs::CObservation3DRangeScan;
	auto o = CObservation3DRangeScan::Create();
	o->sensorLabel = cfg.seq.rgbdLabel;
	o->timestamp = mrpt::Clock::fromDouble(stamp);
	o->sensorPose = mrpt::poses::CPose3D();
	o->maxRange = float(cfg.depth.maxRange);
	o->hasRangeImage = true;
	o->range_is_depth = true;
	o->rangeUnits = 0.001f;
	o->rangeImage_setSize(f.height, f.width);
	for (int v = 0; v < f.height; v++)
		for (int u = 0; u < f.width; u++)
			o->rangeImage(v, u) = f.depthMm[size_t(v) * f.width + u];
	o->cameraParams.ncols = uint32_t(f.width);
	o->cameraParams.nrows = uint32_t(f.height);
	o->cameraParams.setIntrinsicParamsFromValues(
	    cfg.camera.fxS(), cfg.camera.fyS(), cfg.camera.cxS(), cfg.camera.cyS());
	o->cameraParams.distortion = mrpt::img::DistortionModel::none;
	o->cameraParamsIntensity = o->cameraParams;
	o->relativePoseIntensityWRTDepth =
	    mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
	o->hasIntensityImage = cfg.rgb.enabled;
	if (cfg.rgb.enabled)
	{
		o->intensityImageChannel = CObservation3DRangeScan::CH_VISIBLE;
		o->intensityImage.loadFromMemoryBuffer(
		    unsigned(f.width), unsigned(f.height), true, f.rgb.data(), true);
	}
	if (cfg.seq.pixelLabels)
	{
		// Label 0, bit 0 of each pixel; written in one buffer (MRPT's bytes).
		o->pixelLabels = bims::BulkPixelLabels::fromMask(
		    f.mask.data(), f.height, f.width, size_t(f.width), "moving");
	}
	return o;
}

/** RGB | depth (grey, black = no reading) | mask side by side. */
void writePreview(const RenderedFrame& f, double maxRange,
                  const std::string& path)
{
	const int W = f.width, H = f.height;
	cv::Mat img(H, 3 * W, CV_8UC3);
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
		{
			const size_t k = size_t(v) * W + u;
			img.at<cv::Vec3b>(v, u) =
			    cv::Vec3b(f.rgb[3 * k + 2], f.rgb[3 * k + 1], f.rgb[3 * k]);
			const uint8_t d =
			    f.depthMm[k] ? uint8_t(std::clamp(255.0 - 230.0 * f.depthMm[k] *
			                                                  1e-3 / maxRange,
			                                      0.0, 255.0))
			                 : 0;
			img.at<cv::Vec3b>(v, W + u) = cv::Vec3b(d, d, d);
			img.at<cv::Vec3b>(v, 2 * W + u) =
			    cv::Vec3b(f.mask[k], f.mask[k], f.mask[k]);
		}
	writeImageFile(path, img);
}

void writeCalibration(const SimConfig& cfg, const std::string& path)
{
	std::ostringstream f;
	char buf[256];
	const std::string sceneName =
	    cfg.file.substr(cfg.file.find_last_of('/') + 1);
	f << "# bims-sim calibration of scene " << sceneName << "\n"
	  << "# Keys match the sections of a bims experiment .ini.\n"
	  << "[camera]\n";
	std::snprintf(buf, sizeof(buf),
	              "width=%d\nheight=%d\nfx=%.6f\nfy=%.6f\ncx=%.6f\ncy=%.6f\n",
	              cfg.camera.width, cfg.camera.height, cfg.camera.fxS(),
	              cfg.camera.fyS(), cfg.camera.cxS(), cfg.camera.cyS());
	f << buf
	  << "; depth units per metre (TUM convention, as "
	     "config/bonn.ini)\ndepth_scale=1000\n";
	std::snprintf(buf, sizeof(buf), "max_range=%.3f\n", cfg.depth.maxRange);
	f << buf << "\n[calibration]\n"
	  << "; R_IC: orientation of the camera optical frame {C} in the IMU frame "
	     "{I},\n"
	  << "; p_I = R_IC * p_C, 9 numbers row-major.\nR_IC=";
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++)
		{
			std::snprintf(buf, sizeof(buf), "%s%.12f", (r || c) ? " " : "",
			              cfg.imu.R_IC(r, c));
			f << buf;
		}
	std::snprintf(
	    buf, sizeof(buf),
	    "\n; IMU stamp = true time + time_offset_s\ntime_offset_s=%.6f\n",
	    cfg.imu.timeOffsetS);
	f << buf << "\n[sensors]\nrgbd_label=" << cfg.seq.rgbdLabel
	  << "\nimu_label=" << cfg.imu.label << "\n";
	std::snprintf(buf, sizeof(buf), "rgbd_rate_hz=%.6f\nimu_rate_hz=%.6f\n",
	              cfg.seq.fps, cfg.imu.rateHz);
	f << buf;
	const Eigen::Vector3d m = cfg.imu.earthField_W();
	std::snprintf(buf, sizeof(buf),
	              "\n; Earth magnetic field in {W} (z up, x north) [gauss]; "
	              "gravity 9.80665 m/s^2 along -z\n"
	              "; (informative: not a section of the experiment .ini)\n; "
	              "mag_field_W=%.9f %.9f %.9f\n",
	              m.x(), m.y(), m.z());
	f << buf;
	writeFileAtomically(path, f.str());
}

/** The ground truth's files that grow frame by frame beside the rawlog
 * (their headers written at once). */
struct GroundTruthFiles
{
	AppendFile poses, imu, objects;

	explicit GroundTruthFiles(const std::string& gt)
	    : poses(gt + "/groundtruth.txt"),
	      imu(gt + "/imu.txt"),
	      objects(gt + "/objects.txt")
	{
		poses.append(tumHeader(
		    "bims-sim ground truth: camera optical frame poses T_WC, world z "
		    "up, x north"));
		imu.append(imuTruthHeader());
		objects.append(
		    "# bims-sim moving-object poses T_WO (root frame of each object in "
		    "{W}), one line\n"
		    "# per frame and object: frame object_id name t[s] tx ty tz qx qy "
		    "qz qw\n"
		    "# (object_id = the value in RenderedFrame::objectId; masks are "
		    "255 for any id > 0)\n");
	}
	void close()
	{
		for (auto* f : {&poses, &imu, &objects}) f->close();
	}
};

/** The IMU samples into the rawlog and their truth lines, in order. */
struct ImuStream
{
	const SimConfig& cfg;
	ImuSimulator& imu;
	const HandheldMotion& motion;
	RawlogWriter& out;
	AppendFile& truth;
	double t0;        ///< the sequence's start [s]
	size_t next = 0;  ///< samples written

	/** The samples stamped up to sequence time \a tSeq (inclusive); their
	 * truth lines reach the file in one write. */
	void writeUntil(double tSeq)
	{
		std::string lines;
		while (double(next) / cfg.imu.rateHz <= tSeq + 1e-9)
		{
			ImuTruth tr;
			const double stamp = t0 + double(next) / cfg.imu.rateHz;
			out.write(*imu.sample(motion, stamp, t0, &tr));
			lines += imuTruthLine(tr);
			next++;
		}
		truth.append(lines);
	}
};

/** The moving objects' poses at sequence time \a tSeq of frame \a j
 * (objects.txt's lines). */
std::string objectPoseLines(const Scene& scene, int j, double t0, double tSeq)
{
	std::string lines;
	for (size_t o = 0; o < scene.objects.size(); o++)
	{
		Eigen::Matrix3d R;
		Eigen::Vector3d x;
		scene.objects[o]->pose(tSeq, R, x);
		lines += std::to_string(j) + " " + std::to_string(o + 1) + " " +
		         scene.objects[o]->name() + " " +
		         tumLine(t0 + tSeq, toPose(R, x)) + "\n";
	}
	return lines;
}

/** Frame \a j's ground-truth mask (masks/), and the preview if \a preview. */
void writeFrameImages(const SimConfig& cfg, RenderedFrame& frame,
                      const std::string& gt, int j, bool preview)
{
	const cv::Mat mask(frame.height, frame.width, CV_8UC1, frame.mask.data());
	writeImageFile(gt + "/masks/" + frameFileName(j), mask);
	if (preview) writePreview(frame, cfg.depth.maxRange, gt + "/preview.png");
}

/** The share of the frame's pixels on a moving object. */
double movingShare(const RenderedFrame& frame)
{
	size_t nMoving = 0;
	for (auto m : frame.mask) nMoving += m ? 1 : 0;
	return double(nMoving) / double(frame.mask.size());
}
}  // namespace

const OutputFolderLayout& groundTruthLayout()
{
	static const OutputFolderLayout layout{
	    {"groundtruth.txt", "imu.txt", "objects.txt", "calibration.ini",
	     "preview.png"},
	    {{"masks", ".png"}}};
	return layout;
}

SimStats runSimulation(const SimConfig& cfg, const std::string& outRawlog,
                       uint64_t seed, const ProgressCallback& progress,
                       int previewFrame, const std::atomic<bool>* stop)
{
	const auto tStart = std::chrono::steady_clock::now();
	const std::clock_t cpuStart = std::clock();
	SimStats st;
	st.gtDir = groundTruthDirFor(outRawlog);
	// OUT_gt.partial/ beside OUT.rawlog.partial, both put in place at the
	// end: a killed run leaves the earlier pair as it was
	PartialDir gtPart(st.gtDir, groundTruthLayout());
	const std::string gt = gtPart.path();
	makeDirs(gt + "/masks");

	const Scene scene = cfg.buildScene();
	const HandheldMotion motion(cfg.motion);
	const Renderer renderer(cfg.camera, cfg.depth, cfg.rgb);
	ImuSimulator imu(cfg.imu, seed);
	PartialFile part(outRawlog);  // renamed once complete
	RawlogWriter out(part.path(), cfg.seq.gzLevel);

	// The ground truth grows frame by frame beside the rawlog, whose gzip
	// stream is flushed after every frame: a killed run leaves both
	// (OUT.rawlog.partial, OUT_gt.partial/) readable up to the last whole
	// frame (docs/sim.md).
	writeCalibration(cfg, gt + "/calibration.ini");
	GroundTruthFiles truth(gt);
	const double t0 = cfg.seq.startTime;
	ImuStream imuOut{cfg, imu, motion, out, truth.imu, t0};

	Progress rendered;
	rendered.total = size_t(cfg.seq.frames);
	reportProgress(progress, rendered);
	RenderedFrame frame;
	double movingSum = 0;
	int done = 0;  // frames written
	for (; done < cfg.seq.frames && !(stop && *stop); done++)
	{
		const int j = done;
		const double tSeq = double(j) / cfg.seq.fps;
		imuOut.writeUntil(tSeq);
		const Kinematics k = motion.at(tSeq);
		const auto r0 = std::chrono::steady_clock::now();
		renderer.render(scene, tSeq, k.R_WC, k.p_WC, seed, uint64_t(j), frame);
		st.renderSeconds +=
		    std::chrono::duration<double>(std::chrono::steady_clock::now() - r0)
		        .count();
		out.write(*makeScan(cfg, frame, t0 + tSeq));
		out.flush();

		truth.poses.append(tumLine(t0 + tSeq, toPose(k.R_WC, k.p_WC)) + "\n");
		writeFrameImages(cfg, frame, gt, j, j == previewFrame);
		movingSum += movingShare(frame);
		truth.objects.append(objectPoseLines(scene, j, t0, tSeq));
		rendered.done = size_t(j + 1);
		reportProgress(progress, rendered);
	}
	st.interrupted = done < cfg.seq.frames;
	// IMU a little past the last frame written
	imuOut.writeUntil(double(std::max(0, done - 1)) / cfg.seq.fps +
	                  0.5 / cfg.seq.fps);
	out.close();
	truth.close();
	part.commit();
	gtPart.commit();
	rendered.finished = true;
	reportProgress(progress, rendered);

	st.frames = size_t(done);
	st.imuSamples = imuOut.next;
	st.movingFraction = movingSum / std::max(1, done);
	st.cpuSeconds = double(std::clock() - cpuStart) / CLOCKS_PER_SEC;
	st.seconds =
	    std::chrono::duration<double>(std::chrono::steady_clock::now() - tStart)
	        .count();
	return st;
}

}  // namespace bims::sim
