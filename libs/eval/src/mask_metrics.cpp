#include <bims/eval/mask_metrics.h>
#include <bims/io/image_file.h>
#include <map>
#include <tuple>

#include <cmath>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "text_format.h"

namespace bims::eval
{
using detail::fmt4;

namespace
{
std::string sizeText(const cv::Mat& m)
{
	return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}
void checkMask(const cv::Mat& m, const char* what)
{
	if (m.empty()) throw std::invalid_argument(std::string(what) + " is empty");
	if (m.type() != CV_8UC1)
		throw std::invalid_argument(std::string(what) +
		                            " is not an 8-bit single-channel image");
}
double ratio(uint64_t num, uint64_t den)
{
	return den ? static_cast<double>(num) / static_cast<double>(den)
	           : std::numeric_limits<double>::quiet_NaN();
}
}  // namespace

void MaskMetrics::accumulate(const cv::Mat& gt, const cv::Mat& pred,
                             const cv::Mat& validDepth,
                             const LabelConvention& labels)
{
	checkMask(gt, "ground-truth mask");
	checkMask(pred, "predicted mask");
	if (gt.size() != pred.size())
		throw std::invalid_argument("mask sizes differ: ground truth " +
		                            sizeText(gt) + ", prediction " +
		                            sizeText(pred));
	if (!validDepth.empty())
	{
		checkMask(validDepth, "valid-depth mask");
		if (validDepth.size() != gt.size())
			throw std::invalid_argument("valid-depth image is " +
			                            sizeText(validDepth) +
			                            " but the masks are " + sizeText(gt));
	}
	// the class of every label value, once
	LabelClass cls[256];
	for (int i = 0; i < 256; i++) cls[i] = labels.classOf(i);
	MaskMetrics add;
	for (int v = 0; v < gt.rows; v++)
	{
		const uint8_t* g = gt.ptr<uint8_t>(v);
		const uint8_t* p = pred.ptr<uint8_t>(v);
		const uint8_t* d =
		    validDepth.empty() ? nullptr : validDepth.ptr<uint8_t>(v);
		for (int u = 0; u < gt.cols; u++)
		{
			const LabelClass c = cls[g[u]];
			if (c == LabelClass::Unknown)
			{
				const int n = cv::countNonZero(gt == g[u]);
				throw std::invalid_argument(
				    "label value " + std::to_string(g[u]) + " at pixel (" +
				    std::to_string(u) + ", " + std::to_string(v) + ") and " +
				    std::to_string(n - 1) + " other pixels is none of " +
				    labels.describe());
			}
			if (d && !d[u])
			{
				add.invalid++;
				continue;
			}
			if (c == LabelClass::NotScored)
			{
				add.ignored++;
				continue;
			}
			const bool gm = c == LabelClass::Moving, pm = p[u] >= 128;
			if (gm && pm)
				add.tp++;
			else if (pm)
				add.fp++;
			else if (gm)
				add.fn++;
			else
				add.tn++;
		}
	}
	*this += add;  // (nothing added when a value is unknown)
}

MaskMetrics MaskMetrics::compute(const cv::Mat& gt, const cv::Mat& pred,
                                 const cv::Mat& validDepth,
                                 const LabelConvention& labels)
{
	MaskMetrics m;
	m.accumulate(gt, pred, validDepth, labels);
	return m;
}

MaskMetrics& MaskMetrics::operator+=(const MaskMetrics& o)
{
	tp += o.tp;
	fp += o.fp;
	fn += o.fn;
	tn += o.tn;
	invalid += o.invalid;
	ignored += o.ignored;
	return *this;
}

double MaskMetrics::precision() const
{
	return ratio(tp, tp + fp);
}
double MaskMetrics::recall() const
{
	return ratio(tp, tp + fn);
}
double MaskMetrics::f1() const
{
	return ratio(2 * tp, 2 * tp + fp + fn);
}
double MaskMetrics::iou() const
{
	return ratio(tp, tp + fp + fn);
}
double MaskMetrics::staticAsMoving() const
{
	return ratio(fp, fp + tn);
}

std::string MaskMetrics::scoresLine() const
{
	return "precision " + fmt4(precision()) + " recall " + fmt4(recall()) +
	       " F1 " + fmt4(f1()) + " IoU " + fmt4(iou());
}

std::string MaskMetrics::frameScoresLine() const
{
	if (tp + fn > 0) return scoresLine();
	return "no moving label: fp " + std::to_string(fp) + ", static as moving " +
	       fmt4(staticAsMoving());
}

Json MaskMetrics::toJson() const
{
	return {{"tp", tp},
	        {"fp", fp},
	        {"fn", fn},
	        {"tn", tn},
	        {"invalid", invalid},
	        {"ignored", ignored},
	        {"precision", jsonNumber(precision())},
	        {"recall", jsonNumber(recall())},
	        {"f1", jsonNumber(f1())},
	        {"iou", jsonNumber(iou())},
	        {"static_as_moving", jsonNumber(staticAsMoving())}};
}

MaskMetrics voxelMaskMetrics(const cv::Mat& gt, const cv::Mat& pred,
                             const cv::Mat& depthM, double fx, double fy,
                             double cx, double cy, double voxelM)
{
	if (gt.type() != CV_8UC1 || pred.type() != CV_8UC1 ||
	    depthM.type() != CV_32FC1 || gt.size() != pred.size() ||
	    gt.size() != depthM.size())
		throw std::invalid_argument(
		    "voxelMaskMetrics: need CV_8UC1 masks and CV_32FC1 depth of one "
		    "size");
	if (!(voxelM > 0) || !(fx > 0) || !(fy > 0))
		throw std::invalid_argument(
		    "voxelMaskMetrics: voxel size and focal lengths must be > 0");
	struct Count
	{
		uint32_t n = 0, g = 0, p = 0;
	};
	std::map<std::tuple<int64_t, int64_t, int64_t>, Count> cells;
	MaskMetrics m;
	for (int v = 0; v < gt.rows; ++v)
	{
		const float* d = depthM.ptr<float>(v);
		const uint8_t* g = gt.ptr<uint8_t>(v);
		const uint8_t* p = pred.ptr<uint8_t>(v);
		for (int u = 0; u < gt.cols; ++u)
		{
			const double z = d[u];
			if (!(z > 0) || !std::isfinite(z))
			{
				m.invalid++;
				continue;
			}
			const double x = (u - cx) * z / fx, y = (v - cy) * z / fy;
			auto& c = cells[{int64_t(std::floor(x / voxelM)),
			                 int64_t(std::floor(y / voxelM)),
			                 int64_t(std::floor(z / voxelM))}];
			c.n++;
			c.g += g[u] >= 128;
			c.p += p[u] >= 128;
		}
	}
	for (const auto& [k, c] : cells)
	{
		const bool g = 2 * c.g > c.n, p = 2 * c.p > c.n;
		if (g && p)
			m.tp++;
		else if (p)
			m.fp++;
		else if (g)
			m.fn++;
		else
			m.tn++;
	}
	return m;
}

cv::Mat loadMask(const std::string& path, const ImageLimits& limits)
{
	const cv::Mat m =
	    readImageFile(path, cv::IMREAD_UNCHANGED, "mask image", limits);
	if (m.type() != CV_8UC1)
		throw std::runtime_error(
		    path + ": mask must be an 8-bit single-channel PNG (got " +
		    std::to_string(m.channels()) + " channel(s), " +
		    std::to_string(8 * m.elemSize1()) + "-bit)");
	return m;
}

cv::Mat maskOverlay(const cv::Mat& gt, const cv::Mat& pred,
                    const cv::Mat& validDepth, const cv::Mat& background,
                    const std::string& caption)
{
	checkMask(gt, "ground-truth mask");
	checkMask(pred, "predicted mask");
	cv::Mat out(gt.size(), CV_8UC3, cv::Scalar(0, 0, 0));
	if (!background.empty())
	{
		if (background.size() != gt.size())
			throw std::invalid_argument("overlay background is " +
			                            sizeText(background) +
			                            " but the masks are " + sizeText(gt));
		cv::Mat grey;
		if (background.channels() == 3)
			cv::cvtColor(background, grey, cv::COLOR_BGR2GRAY);
		else
			grey = background;
		cv::cvtColor(grey, out, cv::COLOR_GRAY2BGR);
		out *= 0.6;
	}
	for (int v = 0; v < gt.rows; v++)
		for (int u = 0; u < gt.cols; u++)
		{
			auto& px = out.at<cv::Vec3b>(v, u);
			if (!validDepth.empty() && !validDepth.at<uint8_t>(v, u))
			{
				px = cv::Vec3b(40, 40, 40);
				continue;
			}
			const bool gm = gt.at<uint8_t>(v, u) >= 128;
			const bool pm = pred.at<uint8_t>(v, u) >= 128;
			cv::Vec3b c;
			if (gm && pm)
				c = cv::Vec3b(0, 200, 0);  // TP green (BGR)
			else if (pm)
				c = cv::Vec3b(0, 0, 230);  // FP red
			else if (gm)
				c = cv::Vec3b(230, 80, 0);  // FN blue
			else
				continue;
			// Over an image, blend so that the scene stays visible.
			px = background.empty() ? c : 0.4 * px + 0.6 * c;
		}
	cv::rectangle(out, {0, 0}, {out.cols, 22}, cv::Scalar(0, 0, 0), cv::FILLED);
	cv::putText(out, caption, {4, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
	            cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
	const int y = out.rows - 8;
	cv::putText(out, "TP", {4, y}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
	            cv::Scalar(0, 200, 0), 1, cv::LINE_AA);
	cv::putText(out, "FP", {30, y}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
	            cv::Scalar(0, 0, 230), 1, cv::LINE_AA);
	cv::putText(out, "FN", {56, y}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
	            cv::Scalar(230, 80, 0), 1, cv::LINE_AA);
	return out;
}

}  // namespace bims::eval
