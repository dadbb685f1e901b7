// Import of a folder in the TUM RGB-D layout (rgb.txt, depth.txt, optional
// accelerometer.txt and groundtruth.txt; e.g. the Bonn RGB-D Dynamic dataset)
// into a bims rawlog plus ground truth in OUT_gt/ (the simulator's layout).
#pragma once

#include <bims/common/choice.h>
#include <bims/common/progress.h>
#include <bims/io/image_file.h>
#include <bims/io/trajectory.h>
#include <bims/sensors/params.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/obs/CObservation.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace bims::eval
{
/** Pinhole RGB-D camera, registered depth and colour, no distortion.
 * Section [camera] of an experiment .ini. Defaults: the TUM RGB-D "ROS
 * default" intrinsics. */
struct CameraIntrinsics : sensors::PinholeCamera
{
	CameraIntrinsics() : PinholeCamera{640, 480, 525.0, 525.0, 319.5, 239.5} {}
	/** Depth PNG value per metre (TUM, Bonn: 5000, i.e. 0.2 mm units). */
	double depthScale = 5000.0;

	/** Reads keys fx fy cx cy width height depth_scale (all optional);
	 * unknown keys in the section are errors (bims::ConfigSection). */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
	                        const std::string& section = "camera");
};

/** Everything bims-import-tum reads from an experiment .ini: sections
 * [camera], [import], [sensors]. */
/** [import] timestamp: which of a frame's stamps it takes. */
enum class TimestampSource
{
	Depth,
	Rgb
};
inline Choices<TimestampSource> choices(TimestampSource)
{
	static constexpr ChoiceName<TimestampSource> t[] = {
	    {TimestampSource::Depth, "depth"}, {TimestampSource::Rgb, "rgb"}};
	return t;
}

struct ImportParams
{
	CameraIntrinsics camera;
	/** [import] max_time_gap_s: max |t_rgb - t_depth| to pair frames [s]. */
	double maxTimeGap = 0.02;
	/** [import] bonn_gt: apply bonnMarkerToCamera() to groundtruth.txt. */
	bool bonnGt = false;
	/** [import] timestamp: the stamp of a frame. The depth stamp is the
	 * default: the geometry (and the pose) belongs to it. */
	TimestampSource timestampFrom = TimestampSource::Depth;
	/** [import] gt_max_gap_s: ground truth is interpolated at each frame's
	 * stamp only between poses at most this far apart [s]. */
	double gtMaxGap = 0.1;
	/** [import] range_units: metres per unit of the rawlog's uint16 range
	 * image. 0.001 (1 mm) as the simulator and OpenNI2 grabbing; the
	 * rounding (<= 0.5 mm) is far below the sensor's noise. 1/depth_scale
	 * keeps the PNG values exactly. */
	double rangeUnits = 0.001;
	/** [sensors] rgbd_label, imu_label: sensor labels in the rawlog (an
	 * empty value, "any" for rawlog readers, keeps the default). */
	std::string rgbdLabel = "RGBD", imuLabel = "IMU";
	/** [import] accel_label: the sensor label of accelerometer.txt's
	 * samples, a real sensor of its own (accelerometer only): never a
	 * synthetic IMU's label (one with "SYNTH" is refused). */
	std::string accelLabel = "ACCEL";
	/** [input]: the size limits of the folder's image files. */
	ImageLimits images;

	/** Checks the file's sections (bims::checkExperimentSections) and reads
	 * [camera], [import], [sensors], [input] strictly. */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg);
};

/** One associated RGB-D frame of a TUM folder. */
struct TumFrame
{
	double t = 0;  ///< the frame's stamp (depth or rgb, see ImportParams) [s]
	double tRgb = 0, tDepth = 0;     ///< stamps of the two images [s]
	std::string rgbPath, depthPath;  ///< absolute or folder-relative paths
};

/** One line of accelerometer.txt: "timestamp ax ay az" [s, m/s^2]. */
struct AccelSample
{
	double t = 0;
	double a[3] = {0, 0, 0};
};

/** The index of a TUM folder (no images loaded yet). */
struct TumFolder
{
	std::string path;
	std::vector<TumFrame> frames;         ///< associated frames, sorted by t
	size_t rgbCount = 0, depthCount = 0;  ///< lines in rgb.txt, depth.txt
	std::vector<AccelSample> accel;       ///< empty if no accelerometer.txt
	bool hasGroundTruth = false;
	Trajectory groundTruth;  ///< groundtruth.txt as stored (not converted)
};

/** Reads rgb.txt, depth.txt (required), accelerometer.txt and groundtruth.txt
 * (optional) and associates RGB and depth (associateGreedy with
 * params.maxTimeGap). Throws std::runtime_error naming the file and line on
 * missing files, malformed lines or when no frame pairs. */
TumFolder readTumFolder(const std::string& folder, const ImportParams& params);

/** Every file of \a tum the import reads: its lists and the images of its
 * frames (the output guard's inputs). */
std::vector<std::string> tumInputFiles(const TumFolder& tum);

/** Reads a 16-bit depth PNG and returns metres as CV_32F (0 = invalid).
 * Throws naming the file if missing, not 16-bit single channel, or not of
 * the camera's size. */
cv::Mat loadDepthMeters(const std::string& path, const CameraIntrinsics& cam);

/** The observation of one depth PNG alone, stamped \a t (no intensity
 * image): the range image in params.rangeUnits, the camera of
 * params.camera. Throws naming the file as loadDepthMeters. */
mrpt::obs::CObservation3DRangeScan::Ptr loadDepthFrame(
    const std::string& depthPath, double t, const ImportParams& params);

/** Builds the observation of one frame (MRPT_NOTES.md section 5: registered
 * RGB-D, range_is_depth, sensorPose identity, rangeUnits from params):
 * loadDepthFrame and the colour image. */
mrpt::obs::CObservation3DRangeScan::Ptr loadFrame(const TumFrame& frame,
                                                  const ImportParams& params);

struct ImportOptions
{
	size_t maxFrames = 0;  ///< 0 = all
	bool bonnGt = false;   ///< OR-ed with params.bonnGt
	int gzLevel = 1;       ///< 0 = plain rawlog, 1..9 gzip
	/** The frames written (none: silent). */
	ProgressCallback progress;
	/** Extra observations (e.g. synthetic IMU) merged by timestamp; those
	 * outside the imported frames' time span are dropped. */
	std::vector<mrpt::obs::CObservation::Ptr> extra;
};

struct ImportSummary
{
	size_t frames = 0;     ///< 3D scans written
	size_t accel = 0;      ///< accelerometer.txt samples written (accelLabel)
	size_t imu = 0;        ///< other IMU observations written (options.extra)
	std::string imuLabel;  ///< their sensor label (of the first)
	size_t gtPoses = 0;    ///< poses in OUT_gt/groundtruth.txt
	size_t framesWithoutGt = 0;  ///< frames the ground truth did not cover
	std::string gtDir;           ///< OUT_gt folder
	Trajectory groundTruth;  ///< what groundtruth.txt holds (T_WC at frames)
};

/** Imports \a folder into \a outRawlog and writes OUT_gt/calibration.ini
 * ([camera], [sensors]) and, if the folder has ground truth,
 * OUT_gt/groundtruth.txt: T_WC of the camera's optical frame interpolated
 * at each written frame's stamp (Bonn-converted if requested). */
ImportSummary importTum(const std::string& folder, const std::string& outRawlog,
                        const ImportParams& params,
                        const ImportOptions& options);
/** The same for a folder already read (readTumFolder). */
ImportSummary importTum(TumFolder tum, const std::string& outRawlog,
                        const ImportParams& params,
                        const ImportOptions& options);

}  // namespace bims::eval
