// Import of a Stray Scanner capture (the iPhone/iPad LiDAR app) as the app
// writes it: depth/NNNNNN.png (uint16 mm), confidence/NNNNNN.png (ARKit
// 0/1/2), rgb.mp4 (optional), camera_matrix.csv, odometry.csv (ARKit's
// T_world_camera, the frames' clock), imu.csv (accelerometer with Apple's
// sign, gyro) into a bims rawlog of CObservation3DRangeScan +
// CObservationIMU, plus ARKit's poses as a reference trajectory beside it
// (docs/eval.md, "Import of a Stray Scanner capture").
#pragma once

#include <bims/common/options.h>
#include <bims/common/progress.h>
#include <bims/common/warnings.h>
#include <bims/io/image_file.h>
#include <bims/io/trajectory.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/img/TCamera.h>

#include <cstdint>
#include <string>
#include <vector>

namespace bims::eval
{
/** What bims-import-stray reads from an experiment .ini: [import_stray]
 * (describe()) and [sensors] (the labels). */
struct StrayImportParams
{
	/** [import_stray] min_confidence: depth readings whose ARKit confidence
	 * (0 low, 1 medium, 2 high) is below this are written as 0 (none). */
	int min_confidence = 1;
	/** [import_stray] colour_width, colour_height: the size of the colour
	 * stream camera_matrix.csv describes, when there is no rgb.mp4 to take
	 * it from [px]. */
	int colour_width = 1920, colour_height = 1440;
	/** [sensors] rgbd_label, imu_label: the labels written. */
	std::string rgbd_label = "RGBD", imu_label = "IMU";
	/** [input]: the size limits of the capture's depth and confidence
	 * images. */
	ImageLimits images;

	/** The keys of [import_stray] (bims/common/options.h). */
	void describe(OptionVisitor& v);
	/** Checks the file's sections (bims::checkExperimentSections), reads
	 * [import_stray], [sensors] and [input] strictly: unknown keys and values
	 * out of range are errors naming file, section and key. */
	void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg);
};

/** Metres per unit of the rawlog's range image: Stray's depth PNGs hold
 * millimetres, kept exactly. */
constexpr double kStrayRangeUnits = 0.001;

/** The largest time stamp the Stray CSVs may hold [s] (ROS's unsigned
 * 32-bit seconds, to the year 2106); negative stamps are refused too. */
constexpr double kMaxStraySeconds = 4294967295.0;

/** How far camera_matrix.csv's principal point may be from the centre of
 * the colour image it was made for, as a share of its size: the rule that
 * tells which size that was (rgb.mp4's or [import_stray]'s). */
constexpr double kStrayCentreTolerance = 0.2;

/** One row of odometry.csv: a depth frame. */
struct StrayFrame
{
	double t = 0;      ///< the frame's stamp [s] (odometry.csv's timestamp)
	long index = 0;    ///< the frame column: depth/<index, 6 digits>.png
	size_t line = 0;   ///< its line in odometry.csv (1-based)
	double p[3] = {};  ///< x y z: ARKit's T_world_camera translation [m]
	double q[4] = {};  ///< qx qy qz qw as written (unit to 1e-3)
	std::string depthPath, confidencePath;  ///< confidencePath "" without
	                                        ///< the confidence folder

	/** T_WC of the optical frame in ARKit's world (y up). */
	mrpt::poses::CPose3D pose() const;
};

/** One row of imu.csv. */
struct StrayImuSample
{
	double t = 0;
	double a[3] = {};      ///< a_x a_y a_z as written [m/s^2] (Apple's sign)
	double alpha[3] = {};  ///< alpha_x alpha_y alpha_z [rad/s]
};

/** The index of a capture folder (no image read yet). */
struct StrayCapture
{
	std::string path;
	std::vector<StrayFrame> frames;  ///< odometry.csv's rows, in time order
	bool hasConfidence = false;      ///< the confidence/ folder exists
	bool hasImu = false;             ///< imu.csv exists
	std::vector<StrayImuSample> imu;
	std::string videoPath;  ///< FOLDER/rgb.mp4, "" when absent
	double K[3][3] = {};    ///< camera_matrix.csv (the colour stream's)
};

/** Reads odometry.csv (required; header "timestamp, frame, x, y, z, qx, qy,
 * qz, qw"): each row 9 finite numbers, a unit quaternion, time strictly
 * increasing and within [0, kMaxStraySeconds]. Read a row at a time
 * (bims::LineReader: a regular file only, a line at most 64 KiB, a UTF-8
 * byte-order mark skipped, CR, LF or CRLF line ends). Throws
 * std::runtime_error naming the file and the row's line (1-based). */
std::vector<StrayFrame> readStrayOdometry(const std::string& path);

/** Reads imu.csv (header "timestamp, a_x, a_y, a_z, alpha_x, alpha_y,
 * alpha_z"): each row 7 finite numbers, time strictly increasing. Throws
 * as readStrayOdometry. */
std::vector<StrayImuSample> readStrayImu(const std::string& path);

/** Reads camera_matrix.csv: 3 rows "fx, 0, cx", "0, fy, cy", "0, 0, 1"
 * (the last line may lack its newline). Throws naming the file and row. */
void readStrayCameraMatrix(const std::string& path, double K[3][3]);

/** Indexes the folder: odometry.csv, depth/ (every depth/NNNNNN.png has a row
 * and every row its PNG, else an error naming both), camera_matrix.csv,
 * imu.csv and confidence/ when present (a warning once to \a warn when
 * not; confidence that is no folder: an error), rgb.mp4 when present (a
 * note once to \a warn when not; one that is no regular file: an error). */
StrayCapture readStrayCapture(const std::string& folder,
                              const WarningCallback& warn = programWarnings());

/** Every file of \a cap the import reads (the output guard's inputs). */
std::vector<std::string> strayInputFiles(const StrayCapture& cap);

/** The depth grid's intrinsics: camera_matrix.csv's (of a colourWidth x
 * colourHeight colour image) scaled to width x height: fx, cx times
 * width / colourWidth; fy, cy times height / colourHeight. No distortion. */
mrpt::img::TCamera strayDepthCamera(const double K[3][3], int colourWidth,
                                    int colourHeight, int width, int height);

struct StrayImportOptions
{
	size_t maxFrames = 0;  ///< 0 = all
	int gzLevel = 1;       ///< 0 = plain rawlog, 1..9 gzip
	/** The frames written (none: silent). */
	ProgressCallback progress;
	/** What the capture lacks (readStrayCapture()): the program's own
	 * (bims::programWarnings()) unless set. */
	WarningCallback warn = programWarnings();
};

struct StrayImportSummary
{
	size_t frames = 0;          ///< 3D scans written
	size_t imu = 0;             ///< IMU observations written
	size_t imuBeforeFirst = 0;  ///< of them, stamped before the first frame
	int width = 0, height = 0;  ///< the depth grid [px]
	bool colour = false;        ///< rgb.mp4 was there: scans have colour
	int videoWidth = 0, videoHeight = 0;  ///< rgb.mp4's frames [px]
	bool confidence = false;              ///< the confidence/ folder was there
	int minConfidence = 0;                ///< the threshold applied
	uint64_t readings = 0;        ///< depth pixels > 0 in the PNGs written
	uint64_t dropped = 0;         ///< of them, written 0 for low confidence
	mrpt::img::TCamera camera;    ///< the scans' intrinsics
	std::string referencePath;    ///< OUT_arkit_reference.txt
	size_t referencePoses = 0;    ///< poses written there
	size_t referenceLeftOut = 0;  ///< leading frames without position
	Trajectory reference;         ///< what the reference file holds
	/** Frames left out: on the rawlog clock's 100 ns tick of the frame
	 * before (two scans of one stamp: every reader drops one). */
	size_t framesSameStamp = 0;
	/** IMU samples left out: on the tick of the sample before. */
	size_t imuSameStamp = 0;
	/** Samples of imu.csv after the capture's last frame (left out). */
	size_t imuAfterLast = 0;
	/** What the import did that its caller must see (the program prints
	 * each on stderr as a warning): samples or frames left out, and why,
	 * naming the file. */
	std::vector<std::string> warnings;
	/** What the report says besides its figures (a video scaled). */
	std::vector<std::string> notes;
};

/** "OUT_arkit_reference.txt" for "OUT.rawlog" (or OUT.rawlog.gz; the
 * extension removed as groundTruthDirFor does). */
std::string strayReferencePathFor(const std::string& rawlogPath);

/** Imports the capture \a folder into \a outRawlog and writes ARKit's poses
 * at the written frames to strayReferencePathFor(outRawlog), leaving out
 * the leading rows whose translation is exactly 0 (ARKit initialising);
 * both are written as partial files of the run's own and put in place
 * together (bims::commitTogether). Frames and IMU samples (from the start
 * of imu.csv up to the last written frame) in time order, IMU first at
 * equal stamps; a frame or sample on the rawlog clock's 100 ns tick of the
 * one before is left out and counted, samples after the capture's last
 * frame too (StrayImportSummary::warnings says so). The intrinsics on the
 * depth grid must be a camera's (sensors::checkIntrinsics). Throws
 * std::runtime_error naming the file (and row) on bad input. */
StrayImportSummary importStray(const std::string& folder,
                               const std::string& outRawlog,
                               const StrayImportParams& params,
                               const StrayImportOptions& options);
/** The same for a capture already read (readStrayCapture). */
StrayImportSummary importStray(const StrayCapture& cap,
                               const std::string& outRawlog,
                               const StrayImportParams& params,
                               const StrayImportOptions& options);

}  // namespace bims::eval
