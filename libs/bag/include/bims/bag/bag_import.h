// Import of ROS 1 and ROS 2 bags (depth and colour sensor_msgs/Image or
// CompressedImage, CameraInfo, Imu, optional MagneticField) into a bims
// rawlog: the files read by bims (ROS 1: bag_file.h; ROS 2: a bag folder's
// metadata.yaml, MCAP (mcap_file.h) or sqlite3 (db3_file.h)), the messages
// by ROS's own message classes (ROS 1) or bims's CDR decoder (ROS 2), both
// behind one set of message views (messages.h; docs/import-bag.md). Depth and
// colour are paired by stamp as the TUM importer pairs them (associateGreedy);
// IMU samples keep their own stamps; the stamps are the messages' header stamps
// (the sensors' clock), never the bag's record times. A bag of TUM RGB-D's
// layout gives the same rawlog as the TUM folder of the same frames.
#pragma once

#include <bims/common/choice.h>
#include <bims/common/options.h>
#include <bims/common/progress.h>
#include <bims/eval/tum_import.h>
#include <bims/io/image_file.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/img/TCamera.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace bims::bag
{
/** The topic names of the layouts users meet most (--layout). */
enum class BagLayout
{
	Auto,       ///< the first preset whose depth topic the bag has
	RealSense,  ///< realsense-ros: aligned depth, colour, imu or accel+gyro
	Tum,        ///< TUM RGB-D's own bags: depth in metres, accel-only /imu
	/** the RealSense SDK's own recordings (librealsense's "ROS file
	 * format": RealSense Viewer, rs-record): its streams found by name */
	RsSdk
};
inline Choices<BagLayout> choices(BagLayout)
{
	static constexpr ChoiceName<BagLayout> t[] = {
	    {BagLayout::Auto, "auto"},
	    {BagLayout::RealSense, "realsense"},
	    {BagLayout::Tum, "tum"},
	    {BagLayout::RsSdk, "rs-sdk"}};
	return t;
}

/** The topics read. An empty name: not read. */
struct BagTopics
{
	/** sensor_msgs/Image, 16UC1 mm or 32FC1 m, or CompressedImage of
	 * compressed_depth_image_transport (PNG) */
	std::string depth;
	/** sensor_msgs/Image, rgb8 bgr8 mono8, or CompressedImage (JPEG, PNG)
	 */
	std::string colour;
	std::string cameraInfo;  ///< sensor_msgs/CameraInfo of the depth image
	std::string imu;         ///< sensor_msgs/Imu (gyro and/or accel)
	std::string accel;       ///< sensor_msgs/Imu, accelerometer only
	std::string gyro;        ///< sensor_msgs/Imu, gyro only (merged)
	std::string mag;         ///< sensor_msgs/MagneticField
	/** The rs-sdk layout's (found in the bag, never given): the depth
	 * stream's CameraInfo when the depth is registered to the colour
	 * camera by the import (otherwise cameraInfo is the depth's); the
	 * std_msgs/Float32 Depth Units option [m per unit]; each stream's
	 * geometry_msgs/Transform extrinsics (tf/N: from the reference stream
	 * N to the stream, p_stream = R p_ref + t). */
	std::string depthCameraInfo, depthUnits;
	std::string depthTf, colourTf, accelTf, gyroTf;
};

/** The preset topics of \a layout (Auto, RsSdk: none, the latter's
 * streams are found by name: rsSdkTopics()): ROS 1's names. */
BagTopics layoutTopics(BagLayout layout);

/** Every variant of \a layout's preset, in the order they are tried: ROS
 * 1's names first (layoutTopics()), then realsense-ros 4.x's ROS 2 names
 * (/camera/camera/...: aligned depth with colour, else the depth alone,
 * which is not registered to the colour). The import reads the first whose
 * depth topic the recording has. */
std::vector<BagTopics> layoutVariants(BagLayout layout);

/** What bims-import-bag reads from an experiment .ini: [import_bag]
 * (describe()), [camera] (intrinsics overriding the bag's CameraInfo: all
 * of fx fy cx cy width height or none), [sensors] (the labels) and [input]
 * (the limits of compressed images). */
struct BagImportParams
{
	/** [import_bag] layout (--layout overrides): whose preset topics. */
	BagLayout layout = BagLayout::Auto;
	/** [import_bag] depth_topic ... mag_topic: each replaces the preset's
	 * topic when given ("none": not read). */
	BagTopics topics;
	/** [import_bag] max_time_gap_s: max |t_colour - t_depth| to pair. */
	double maxTimeGap = 0.02;
	/** [import_bag] timestamp: the stamp of a frame (depth by default). */
	eval::TimestampSource timestampFrom = eval::TimestampSource::Depth;
	/** [import_bag] depth_units: metres per unit of an rs-sdk recording's
	 * 16-bit depth (0: the recording's Depth Units option, else the
	 * units its depth images carry); given, it replaces the recording's.
	 * --depth-units overrides. */
	double depthUnits = 0;
	/** [import_bag] range_units: metres per unit of the range image. */
	double rangeUnits = 0.001;
	/** [import_bag] accel_label: the label of IMU samples without a gyro
	 * (TUM's accelerometer), as bims-import-tum's [import] accel_label. */
	std::string accelLabel = "ACCEL";
	/** [camera] when the file gives it: the bag's CameraInfo is then only
	 * checked against the image size. */
	std::optional<mrpt::img::TCamera> camera;
	std::string cameraFrom;  ///< "[camera] of FILE" when given
	/** [sensors] rgbd_label, imu_label. */
	std::string rgbdLabel = "RGBD", imuLabel = "IMU";
	/** [input] image_max_side, image_max_pixels: a compressed image
	 * (sensor_msgs/CompressedImage) declaring more is refused before it
	 * is decoded. */
	ImageLimits images;

	/** The keys of [import_bag] (bims/common/options.h). */
	void describe(OptionVisitor& v);
	/** Checks the file's sections (bims::checkExperimentSections) and reads
	 * [import_bag], [camera] and [sensors] strictly: unknown keys and values
	 * out of range are errors naming file, section and key. */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg);
};

/** The topics read with \a layout (not Auto): the preset's, each replaced
 * by the one \a given names ("none": not read). */
BagTopics resolveTopics(const BagTopics& given, BagLayout layout);
/** The same over the topics \a preset (a variant of a layout). */
BagTopics resolveTopics(const BagTopics& given, const BagTopics& preset);

/** One topic of a bag: name, message type, message count. */
struct BagTopicInfo
{
	std::string name, type;
	size_t messages = 0;
};

/** The topics of \a bagPaths (all bags together), sorted by name: from a
 * bag's index when it is whole, else counted in its chunks (a recording
 * cut short). Throws std::runtime_error naming the bag when it cannot be
 * opened (missing, not a ROS 1 bag of format 2.0). A bag cut short or
 * damaged adds a line to \a damage, when given: "BAG: cut short or
 * damaged: ..." (its topics are those before the damage). */
std::vector<BagTopicInfo> bagTopics(const std::vector<std::string>& bagPaths,
                                    std::vector<std::string>* damage = nullptr);

/** "  /camera/imu  sensor_msgs/Imu  2000 messages" lines. */
std::string describeTopics(const std::vector<BagTopicInfo>& topics);

/** The layout whose depth topic \a topics has (RealSense first); throws
 * naming the bags and listing their topics when none does. */
BagLayout detectLayout(const std::vector<BagTopicInfo>& topics,
                       const std::string& bagNames);

/** The streams of a RealSense SDK recording among \a topics, found by
 * their names (/device_D/sensor_S/<Stream>_I/...: the sensor numbers vary
 * by model): the first device's first Depth stream, its camera_info,
 * tf and its sensor's Depth Units option ("Depth Units" or
 * "Depth_Units", as librealsense versions name it), the first Color
 * stream (its CameraInfo then cameraInfo, the depth's depthCameraInfo),
 * the Accel and Gyro streams. depth is empty when there is none. */
BagTopics rsSdkTopics(const std::vector<BagTopicInfo>& topics);

/** A rigid transform p_to = R p_from + t (R row major) [m]. */
struct RigidTransform
{
	double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
	double t[3] = {0, 0, 0};
};
/** The angle of \a a's rotation [deg]. */
double rotationDeg(const RigidTransform& a);

/** One IMU sample of the merged stream [s, rad/s, m/s^2, T]. */
struct ImuSample
{
	double t = 0;
	bool hasGyro = false, hasAccel = false, hasMag = false;
	double w[3] = {}, a[3] = {}, m[3] = {};
	/** sensor_msgs/Imu's orientation when its covariance says it is given
	 * (x y z w; the import does not use it, the ROS 2 node passes it on). */
	bool hasOrientation = false;
	double q[4] = {0, 0, 0, 1};
};

/** Merges separate accelerometer and gyro streams (time-sorted) into whole
 * samples at the gyro's stamps: the accelerometer linearly interpolated
 * between its two samples around each gyro stamp. Gyro samples outside the
 * accelerometer's time span are left out and counted in \a leftOut. */
std::vector<ImuSample> mergeAccelGyro(const std::vector<ImuSample>& accel,
                                      const std::vector<ImuSample>& gyro,
                                      size_t& leftOut);

/** Adds the magnetometer (time-sorted) to \a imu, linearly interpolated
 * at each sample's stamp within the magnetometer's time span (outside:
 * none). */
void attachMagnetometer(std::vector<ImuSample>& imu,
                        const std::vector<ImuSample>& mag);

/** A ROS stamp (sec, nsec) as seconds, correctly rounded (the double
 * nearest to the decimal "sec.nnnnnnnnn", as a TUM file's stamp is
 * parsed). A non-canonical stamp, nsec >= 1e9, is normalised as ROS does:
 * the whole seconds of nsec carried into sec (999 s 1e9 ns = 1000.0 s). */
double stampSeconds(uint32_t sec, uint32_t nsec);

struct BagImportOptions
{
	size_t maxFrames = 0;  ///< 0 = all
	int gzLevel = 1;       ///< 0 = plain rawlog, 1..9 gzip
	/** Bytes of decompressed BZ2 chunks kept from the scan of the bags to
	 * the reading of their images: a bag whose chunks fit is decompressed
	 * once, a larger one partly twice (LZ4 chunks: always twice, which
	 * costs less than keeping them). */
	size_t chunkCacheBytes = size_t{1} << 30;
	/** The frames written (none: silent). */
	ProgressCallback progress;
};

struct BagImportSummary
{
	size_t frames = 0;                             ///< 3D scans written
	size_t depthMessages = 0, colourMessages = 0;  ///< read in the bags
	size_t unpaired = 0;       ///< depth images without colour within the gap
	size_t stampsBack = 0;     ///< images whose stamp was not after the last
	size_t imu = 0;            ///< IMU observations written (imuLabel)
	size_t accelOnly = 0;      ///< of them, accelerometer only (accelLabel)
	size_t imuLeftOut = 0;     ///< gyro samples outside the accel's span
	size_t imuStampsBack = 0;  ///< IMU samples not after the last, left out
	size_t imuOutside = 0;     ///< IMU samples outside the frames' time span
	bool imuHasGyro = false, imuHasAccel = false, imuHasMag = false;
	std::string imuSource;      ///< "imu topic /x", "accel /a + gyro /g merged"
	int width = 0, height = 0;  ///< the images [px]
	std::string depthEncoding, colourEncoding;
	mrpt::img::TCamera camera;  ///< the scans' intrinsics
	std::string cameraFrom;     ///< "CameraInfo /x" or "[camera] of FILE"
	/** The CameraInfo has non-zero distortion coefficients, which the
	 * pinhole model of bims leaves out (images are not undistorted). */
	bool distortionIgnored = false;
	/** CameraInfo messages that differ (size or K) from the first, which
	 * is used for every frame (a note says so), and the first of them (its
	 * index on the topic). */
	size_t cameraInfoChanges = 0, firstCameraInfoChange = 0;
	std::string distortionModel;  ///< its distortion_model then
	BagTopics topics;             ///< the topics read
	/** Damage that lost nothing imported (an index damaged at the bag's
	 * end; damage after the --max-frames imported), one line each. */
	std::vector<std::string> notes;
	BagLayout layout = BagLayout::Auto;  ///< whose presets (Auto: none)
	/** rs-sdk: metres per unit of the depth images, and where from. */
	double depthUnits = 0;
	std::string depthUnitsFrom;
	/** rs-sdk with colour: the depth camera to the colour camera (the
	 * depth registered to the colour with it), from the tf topics. */
	std::optional<RigidTransform> depthToColour;
	/** rs-sdk: the frames' camera to the IMU (the gyro's tf): R is
	 * [calibration] R_IC (p_I = R_IC p_C + t). */
	std::optional<RigidTransform> cameraToImu;
	std::string cameraToImuFrom;  ///< "tf /a and /b"
	/** rs-sdk: OUT_gt/calibration.ini ([camera], [calibration] R_IC,
	 * [sensors]) written beside the rawlog; empty: none. */
	std::string calibrationFile;
};

/** Imports \a bagPaths (read as one recording: ROS 1 bag files, ROS 2 bag
 * folders (their metadata.yaml's files), .mcap or .db3 files, each kind
 * known by its first bytes) into \a outRawlog (written
 * as OUT.rawlog.partial, renamed when complete): frames and IMU samples in
 * time order, IMU first at equal stamps; IMU samples outside the frames'
 * time span are left out as the TUM importer does. Throws
 * std::runtime_error naming the bag (and topic, message and stamp) on bad
 * input: a missing topic (listing the topics the bags have), a wrong
 * encoding, a CameraInfo that disagrees with the image size, a message that
 * cannot be read. When a message of a frame cannot be read, the whole
 * frames before it are kept: the rawlog is renamed into place with them,
 * and the error says how many. So it is when a bag is cut short or damaged
 * (its messages are read from its chunks, not its index): every whole frame
 * before the damage is written, and the error names the bag and the byte. */
BagImportSummary importBag(const std::vector<std::string>& bagPaths,
                           const std::string& outRawlog,
                           const BagImportParams& params,
                           const BagImportOptions& options);

}  // namespace bims::bag
