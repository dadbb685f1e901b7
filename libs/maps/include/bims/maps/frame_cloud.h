// One frame's registered readings, keyed once and shared by the three tiers.
//
// Built from a CObservation3DRangeScan and the pose T_WS of MRPT's scan frame
// {S} in the world {W} (bims/common/frames.h); the optical frame is
// T_WC = T_WS * T_SC. Every valid pixel becomes a point in {W} with its
// pixel index and the index of its voxel among the frame's distinct hit
// voxels (cells), so unprojection and voxel keying happen once per frame.
#pragma once

#include <bims/common/depth_image.h>
#include <bims/maps/flat_hash_map.h>
#include <bims/maps/grid_params.h>
#include <bims/maps/pixel_maps.h>
#include <bims/maps/voxel_key.h>
#include <bims/sensors/params.h>

#include <mrpt/core/Clock.h>
#include <mrpt/math/TPoint3D.h>
#include <mrpt/poses/CPose3D.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace mrpt::obs
{
class CObservation3DRangeScan;
}

namespace bims::maps
{
/** Readings skipped while building a frame, by reason. */
struct FrameStats
{
	size_t valid = 0;          //!< readings used
	size_t noDepth = 0;        //!< zero depth (no reading)
	size_t nonFinite = 0;      //!< NaN or inf coordinates
	size_t beyondRange = 0;    //!< farther than max_range
	size_t outsideExtent = 0;  //!< outside the configured extent
	size_t overBudget = 0;     //!< cells not created: memory budget
	bool badPose = false;      //!< the pose was not finite: frame skipped
	FrameStats& operator+=(const FrameStats& o);
	size_t skipped() const
	{
		return noDepth + nonFinite + beyondRange + outsideExtent + overBudget;
	}
	std::string asString() const;
};

/** See the file comment. */
struct FrameCloud
{
	/** Voxel size the keys were computed for [m]. */
	double voxel_size = 0;
	/** Observation time (used to recognise a frame already folded into a
	 * linked tier-0 map); INVALID_TIMESTAMP if unknown. */
	mrpt::Clock::time_point timestamp{};
	/** Pose of the optical frame {C} in {W}. */
	mrpt::poses::CPose3D T_WC;
	/** Sensor origin in {W} [m]. */
	mrpt::math::TPoint3D origin_W;
	/** The camera model; width = height = 0 for an unorganised cloud (then
	 * decay = frustum has no frustum and masks are empty). */
	sensors::PinholeCamera K;
	/** Per pixel (row-major) depth used [m] along the optical axis, 0 where
	 * no valid reading; empty for an unorganised cloud. */
	std::vector<float> depth;

	/** Valid readings in {W} [m]. */
	std::vector<mrpt::math::TPoint3Df> points_W;
	/** Pixel index v * width + u of each reading. */
	std::vector<uint32_t> pixel;
	/** Index into cells of each reading's voxel. */
	std::vector<uint32_t> cellOfPoint;
	/** Distinct voxels hit this frame, ordered by storage block (8^3) and
	 * by cell inside a block. */
	std::vector<VoxelKey> cells;
	/** Number of readings in each of cells (n_C >= 1). */
	std::vector<uint32_t> hits;

	FrameStats stats;

	size_t numPoints() const { return points_W.size(); }
	size_t numCells() const { return cells.size(); }
};

/** Builds FrameCloud objects, reusing its scratch memory across frames.
 * Not thread-safe (one builder per thread). */
class FrameCloudBuilder
{
 public:
	explicit FrameCloudBuilder(const GridParams& p = {});
	void setParams(const GridParams& p);

	/** From a depth/range image (readings x units; Euclidean ranges when
	 * \a img.isDepth is false), unprojected with the camera model \a K
	 * (its size must be the image's) at the pose \a T_WC of the optical
	 * frame {C} in {W}: the caller's camera model and pose, the ones its
	 * egomotion and flow use. A non-finite pose yields an empty frame with
	 * stats.badPose = true. Throws std::invalid_argument if the image is
	 * empty, \a K's size differs from it or its focal lengths are not
	 * > 0. */
	void build(const DepthImage& img, const sensors::PinholeCamera& K,
	           const mrpt::poses::CPose3D& T_WC, FrameCloud& out);
	/** The same from a scan's range image (depthImageOf(scan)): the scan's
	 * own cameraParams and sensorPose are not read. */
	void build(const mrpt::obs::CObservation3DRangeScan& scan,
	           const sensors::PinholeCamera& K,
	           const mrpt::poses::CPose3D& T_WC, FrameCloud& out);
	/** The same in MRPT's convention (CMetricMap::insertObservation): the
	 * scan's own cameraParams, and \param T_WS the pose of MRPT's scan
	 * frame {S} in {W} (the observation's sensorPose is NOT added: pass
	 * robotPose + sensorPose yourself). */
	void build(const mrpt::obs::CObservation3DRangeScan& scan,
	           const mrpt::poses::CPose3D& T_WS, FrameCloud& out);

	/** From points already in {W}, with the sensor origin (e.g. a
	 * simulator or a LiDAR). \a pixels may be empty (unorganised cloud). */
	void buildFromPoints(const std::vector<mrpt::math::TPoint3Df>& points_W,
	                     const std::vector<uint32_t>& pixels,
	                     const mrpt::math::TPoint3D& origin_W, FrameCloud& out,
	                     const sensors::PinholeCamera& K = {});

	/** Keys the points of \a out (points_W, pixel already filled):
	 * fills cellOfPoint, cells, hits and the extent/range statistics. */
	void keyPoints(FrameCloud& out);

 private:
	struct Keyer;
	/** Sorts the nRuns_ runs of runKey_/runStart_ into out.cells, out.hits and
	 * out.cellOfPoint (out.points_W holds the kept readings, out.cellOfPoint
	 * the run of each), through the entries below. */
	void finishCells(FrameCloud& out);
	// Sort the nEntries_ entries into cells (entryCell_; out.cells and
	// out.hits have a slot per entry), returning the number of cells; block
	// bounds in the offset coordinates of packed keys (field >> 3).
	uint32_t bucketCells(FrameCloud& out, const uint32_t lo[3],
	                     const size_t nb[3]);
	uint32_t radixCells(FrameCloud& out, const uint32_t lo[3],
	                    const uint32_t hi[3]);

	GridParams p_;
	// Per-column terms of the unprojection, one array each of width W:
	// 1 + xn^2, then xn * R_WC.col(0) (x, y, z).
	std::vector<double> colTab_;
	// Runs of consecutive kept readings in one voxel: packed key (packKey)
	// and first reading (nRuns_ of them; the vectors only grow, one slot
	// more than readings), and each run's entry.
	std::vector<uint64_t> runKey_;
	std::vector<uint32_t> runStart_, runEntry_;
	size_t nRuns_ = 0;
	// Entries (runs of one voxel merged through a cache of recent keys,
	// see finishCells()): key, readings, cell; and the cache.
	std::vector<uint64_t> entryKey_;
	std::vector<uint32_t> entryHits_, entryCell_;
	std::vector<uint64_t> cache_;
	size_t nEntries_ = 0;
	// bucketCells() packs an entry's index in 23 bits: frames with more
	// entries take radixCells().
	static constexpr uint32_t kMaxBucketEntries = uint32_t(1) << 23;
	// Sort scratch: (compact key << entry bits) | entry, or (key, entry)
	// pairs; (entry << 9) | cell per block.
	std::vector<uint64_t> packed_, packedTmp_;
	std::vector<std::pair<uint64_t, uint32_t>> pairs_;
	std::vector<uint32_t> byBlock_;
	std::vector<uint32_t> bucketStart_;
};

}  // namespace bims::maps
