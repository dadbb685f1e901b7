// Pixel-level segmentation metrics: a predicted moving-pixel mask against a
// ground-truth mask, counted over the pixels with valid depth.
#pragma once

#include <bims/eval/mask_labels.h>
#include <bims/io/image_file.h>
#include <bims/io/json.h>
#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

namespace bims::eval
{
/** Confusion counts of "moving" pixels and the derived scores. Scores whose
 * denominator is zero are NaN (e.g. recall on a frame with nothing moving);
 * they are printed as "nan" and written as JSON null. */
struct MaskMetrics
{
	uint64_t tp = 0;       ///< moving in GT and prediction
	uint64_t fp = 0;       ///< predicted moving, static in GT
	uint64_t fn = 0;       ///< moving in GT, predicted static
	uint64_t tn = 0;       ///< static in both
	uint64_t invalid = 0;  ///< pixels skipped (no valid depth)
	uint64_t ignored = 0;  ///< pixels whose label is a value not scored

	/** Adds the counts of one frame. \a gt and \a pred are CV_8UC1 masks;
	 * \a gt's values are read with \a labels (by default the contract:
	 * >= 128 moving, the contract writes 0/255), \a pred's by the contract;
	 * \a validDepth is empty (all pixels count) or CV_8UC1 of the same size
	 * (non-zero = valid). Throws std::invalid_argument on empty masks, other
	 * types, different sizes or a label value \a labels does not know
	 * (naming the value, a pixel holding it and how many do). */
	void accumulate(const cv::Mat& gt, const cv::Mat& pred,
	                const cv::Mat& validDepth = cv::Mat(),
	                const LabelConvention& labels = LabelConvention());
	/** The counts of one frame (see accumulate()). */
	static MaskMetrics compute(
	    const cv::Mat& gt, const cv::Mat& pred,
	    const cv::Mat& validDepth = cv::Mat(),
	    const LabelConvention& labels = LabelConvention());

	MaskMetrics& operator+=(const MaskMetrics& o);

	double precision() const;  ///< tp / (tp + fp)
	double recall() const;     ///< tp / (tp + fn)
	double f1() const;         ///< 2 tp / (2 tp + fp + fn)
	double iou() const;        ///< tp / (tp + fp + fn)
	/** fp / (fp + tn): the share of the static pixels called moving. */
	double staticAsMoving() const;
	uint64_t valid() const { return tp + fp + fn + tn; }

	/** "precision P recall R F1 F IoU I" with 4 decimals ("nan" if
	 * undefined). */
	std::string scoresLine() const;
	/** One frame's figures: scoresLine(), or for a frame without a moving
	 * label (where precision and F1 are 0 or undefined whatever the
	 * segmentation does) its false positives, "no moving label: fp N,
	 * static as moving S". */
	std::string frameScoresLine() const;
	/** JSON object with counts and scores. */
	Json toJson() const;
};

/** Voxel-level counts of one frame: the pixels with valid \a depthM
 * (CV_32FC1 metres along the optical axis, 0/NaN = none) are back-projected
 * with the pinhole (fx, fy, cx, cy) into the camera frame and binned into
 * cubes of edge \a voxelM; a cube is moving in the ground truth (in the
 * prediction) when more than half of its pixels are. Each 3D cell counts
 * once, however many pixels see it, so near surfaces do not outweigh far
 * ones as they do at pixel level. Throws std::invalid_argument on
 * inconsistent sizes or a non-positive voxel or focal length. */
MaskMetrics voxelMaskMetrics(const cv::Mat& gt, const cv::Mat& pred,
                             const cv::Mat& depthM, double fx, double fy,
                             double cx, double cy, double voxelM);

/** Reads an 8-bit single-channel mask PNG (its size checked against
 * \a limits first); throws std::runtime_error naming the file if it is
 * missing, unreadable, too large or of another type. */
cv::Mat loadMask(const std::string& path, const ImageLimits& limits = {});

/** Colour overlay of one frame (BGR): TP green, FP red, FN blue (blended
 * 60 % over the \a background when one is given), invalid pixels dark grey,
 * other pixels the dimmed grey \a background (CV_8UC1 or CV_8UC3 of the same
 * size; black if empty). A caption line with the frame's
 * scores is drawn at the top. */
cv::Mat maskOverlay(const cv::Mat& gt, const cv::Mat& pred,
                    const cv::Mat& validDepth, const cv::Mat& background,
                    const std::string& caption);

}  // namespace bims::eval
