// Label folders for mask scoring: how a label image encodes its classes
// (a value for "moving", one for "static", values not scored), how mask
// files are named (by scan index or by timestamp), and which prediction
// scores against which label (by index, or by timestamp within a tolerance).
#pragma once

#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace bims::eval
{
/** The classes of a label value. */
enum class LabelClass
{
	Static,
	Moving,
	NotScored,  ///< e.g. ambiguous or without depth
	Unknown     ///< none of the convention's values: an error
};

/** How a label image encodes its classes. The default is the bims
 * contract (any value >= 128 moving, any other static, nothing ignored);
 * a convention with explicit values accepts only those. */
struct LabelConvention
{
	int moving = -1;           ///< value meaning moving; -1: >= 128 (contract)
	int staticValue = -1;      ///< value meaning static; -1: < 128 (contract)
	std::vector<int> ignored;  ///< values not scored
	/** Explicit values: moving (default 255 when only the others are
	 * given), static (default 0), ignored (may be empty). Throws
	 * std::invalid_argument for values outside 0-255 or one value given
	 * two classes. */
	static LabelConvention explicitValues(int moving, int staticValue,
	                                      const std::vector<int>& ignored);
	bool isContract() const { return moving < 0; }
	LabelClass classOf(int value) const;
	/** "moving 255, static 0, not scored 150 50" (or the contract's). */
	std::string describe() const;
	/** A label image (CV_8UC1) in the contract's terms: \a moving 255
	 * where the label means moving, else 0; \a scored 255 where it means
	 * moving or static, else 0 (not scored, or unknown: accumulate()
	 * reports those). */
	void toContract(const cv::Mat& labels, cv::Mat& moving,
	                cv::Mat& scored) const;
};

/** Parses "150,50" (or "150 50"): values 0-255; throws
 * std::invalid_argument naming the bad item. */
std::vector<int> parseLabelValues(const std::string& text);

/** The file in a label folder that declares its values: "labels.ini",
 * section [labels], keys moving, static (0-255) and not_scored (a list). */
inline constexpr const char* kLabelConventionFile = "labels.ini";

/** The convention \a dir declares in its labels.ini; nullopt when it has
 * none. The file is read strictly (unknown keys, bad values: ConfigError or
 * std::invalid_argument naming the file). */
std::optional<LabelConvention> readLabelConventionFile(const std::string& dir);

/** How many pixels (and label images) hold each value. */
struct LabelValueCounts
{
	std::array<uint64_t, 256> pixels{};  ///< pixels of each value
	std::array<size_t, 256> images{};    ///< label images holding it
	/** The first image (0: the first added) holding each value. */
	std::array<size_t, 256> firstImage{};
	size_t nImages = 0;               ///< label images counted
	void add(const cv::Mat& labels);  ///< CV_8UC1
	/** The values present that \a c classes as unknown, ascending. */
	std::vector<int> unknown(const LabelConvention& c) const;
	/** "0: 1234 px in 3 labels, 255: ..." over the values present, each
	 * with its class under \a c ("moving", "static", "not scored" or
	 * "unknown"). */
	std::string describe(const LabelConvention& c) const;
};

/** A mask file: named NNNNNN.png (index of the 3D scan, from 0) or
 * SECONDS.png (a timestamp, as TUM-style folders name their images). */
struct MaskFile
{
	std::string name;  ///< file name (no folder)
	long index = -1;   ///< NNNNNN, or -1
	double stamp = 0;  ///< SECONDS when named by time (index = -1)
	bool byTime() const { return index < 0; }
};

/** The .png files of \a dir, all named the same way (all NNNNNN or all
 * SECONDS), sorted by index or stamp. Throws std::runtime_error naming the
 * folder if it is missing or holds no mask, and naming the first file
 * that is neither or that mixes the two ways. */
std::vector<MaskFile> listMaskFiles(const std::string& dir);

/** Stamps of a run's frames from its frames.csv (bims-run: columns
 * "index" and "t" in the header): index -> t [s]. Throws
 * std::runtime_error naming the file (and line) when it is missing, has no
 * such columns or a malformed row. */
std::map<long, double> readFrameStamps(const std::string& csvPath);

/** A label scored against a prediction. */
struct MaskPair
{
	const MaskFile* label = nullptr;
	const MaskFile* pred = nullptr;
	double dt = 0;  ///< |t_label - t_pred| [s] (0 when matched by index)
};

/** Which prediction scores against which label. */
struct MaskMatch
{
	std::vector<MaskPair> pairs;  ///< sorted by label
	/** Labels without a prediction (e.g. frames the importer dropped). */
	std::vector<const MaskFile*> labelsWithoutPrediction;
	/** Those of them outside the predictions' span (before the first or
	 * after the last, by index, or by time beyond the tolerance): a run of
	 * part of the labelled frames (bims-run --frames A:B). */
	std::vector<const MaskFile*> labelsOutsidePredictions;
	/** Predictions inside the labels' span without a label: by index, no
	 * label of their index between the first label's and the last's; by
	 * time, none within the tolerance. A label folder with missing
	 * frames. */
	std::vector<const MaskFile*> predictionsWithoutLabel;
	/** Predictions outside the labels' span (a longer run): not scored. */
	int predictionsOutside = 0;
};

/** Matches by index when both folders are named by index, else by time:
 * each side's stamp is its name's or, for a prediction named by index,
 * \a predStamps[index] (a prediction without a stamp is an error naming
 * it). Pairs are one to one, closest first, |dt| <= \a maxDt
 * (associateGreedy). Throws std::runtime_error when labels are named by
 * index but predictions by time. */
MaskMatch matchMasks(const std::vector<MaskFile>& labels,
                     const std::vector<MaskFile>& preds,
                     const std::map<long, double>& predStamps, double maxDt);

}  // namespace bims::eval
