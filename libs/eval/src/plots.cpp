#include <bims/common/output_paths.h>
#include <bims/eval/plots.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace bims::eval
{
namespace
{
const cv::Scalar kGtColour(0, 0, 0), kEstColour(0, 0, 220),
    kPairColour(190, 190, 190), kTextColour(40, 40, 40);

double coord(const mrpt::poses::CPose3D& p, int axis)
{
	return axis == 0 ? p.x() : (axis == 1 ? p.y() : p.z());
}

/** A "nice" length (1, 2 or 5 times a power of ten) close to x. */
double niceLength(double x)
{
	if (!(x > 0)) return 1;
	const double p = std::pow(10.0, std::floor(std::log10(x)));
	const double m = x / p;
	return (m < 1.5 ? 1 : (m < 3.5 ? 2 : 5)) * p;
}

/** Draws one view (horizontal axis ax, vertical axis ay) into \a panel. */
void drawView(cv::Mat& panel, const Trajectory& gt, const Trajectory& est,
              const IndexPairs& pairs, int ax, int ay, const std::string& name)
{
	const char* axisNames = "xyz";
	const int margin = 50;
	double lo[2] = {std::numeric_limits<double>::max(),
	                std::numeric_limits<double>::max()};
	double hi[2] = {-lo[0], -lo[1]};
	for (const auto* tr : {&gt, &est})
		for (const auto& p : *tr)
		{
			const double c[2] = {coord(p.T_WC, ax), coord(p.T_WC, ay)};
			for (int k = 0; k < 2; k++)
			{
				lo[k] = std::min(lo[k], c[k]);
				hi[k] = std::max(hi[k], c[k]);
			}
		}
	if (lo[0] > hi[0]) return;  // nothing to draw
	const double w = panel.cols - 2 * margin, h = panel.rows - 2 * margin - 30;
	const double span =
	    std::max({hi[0] - lo[0], (hi[1] - lo[1]) * w / h, 1e-3});
	const double scale = w / span;  // px per metre
	const double c0 = 0.5 * (lo[0] + hi[0]), c1 = 0.5 * (lo[1] + hi[1]);
	auto px = [&](const mrpt::poses::CPose3D& p)
	{
		return cv::Point(
		    static_cast<int>(
		        std::lround(panel.cols / 2.0 + (coord(p, ax) - c0) * scale)),
		    static_cast<int>(std::lround(30 + margin + h / 2.0 -
		                                 (coord(p, ay) - c1) * scale)));
	};
	for (const auto& [g, e] : pairs)
		if (g < gt.size() && e < est.size())
			cv::line(panel, px(gt[g].T_WC), px(est[e].T_WC), kPairColour, 1,
			         cv::LINE_AA);
	for (const auto& [tr, col] :
	     {std::make_pair(&gt, kGtColour), std::make_pair(&est, kEstColour)})
		for (size_t i = 1; i < tr->size(); i++)
			cv::line(panel, px((*tr)[i - 1].T_WC), px((*tr)[i].T_WC), col, 2,
			         cv::LINE_AA);
	if (!gt.empty()) cv::circle(panel, px(gt.front().T_WC), 4, kGtColour, 2);
	if (!est.empty()) cv::circle(panel, px(est.front().T_WC), 4, kEstColour, 2);

	const std::string label =
	    name + " (" + axisNames[ax] + " right, " + axisNames[ay] + " up)";
	cv::putText(panel, label, {margin, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.55,
	            kTextColour, 1, cv::LINE_AA);
	// Scale bar.
	const double len = niceLength(span / 4);
	const int bar = static_cast<int>(std::lround(len * scale));
	const int y = panel.rows - 18;
	cv::line(panel, {margin, y}, {margin + bar, y}, kTextColour, 2);
	cv::line(panel, {margin, y - 5}, {margin, y + 5}, kTextColour, 2);
	cv::line(panel, {margin + bar, y - 5}, {margin + bar, y + 5}, kTextColour,
	         2);
	char txt[64];
	std::snprintf(txt, sizeof(txt), "%g m", len);
	cv::putText(panel, txt, {margin + bar + 8, y + 5}, cv::FONT_HERSHEY_SIMPLEX,
	            0.5, kTextColour, 1, cv::LINE_AA);
}
}  // namespace

cv::Mat plotTrajectories(const Trajectory& gt, const Trajectory& estAligned,
                         const IndexPairs& pairs, const std::string& title)
{
	const int pw = 600, ph = 600, top = 40;
	cv::Mat img(ph + top, 2 * pw, CV_8UC3, cv::Scalar(255, 255, 255));
	cv::Mat left = img(cv::Rect(0, top, pw, ph));
	cv::Mat right = img(cv::Rect(pw, top, pw, ph));
	drawView(left, gt, estAligned, pairs, 0, 1, "top view");
	drawView(right, gt, estAligned, pairs, 0, 2, "side view");
	cv::line(img, {pw, top}, {pw, top + ph}, kPairColour, 1);
	cv::putText(img, title, {10, 26}, cv::FONT_HERSHEY_SIMPLEX, 0.6,
	            kTextColour, 1, cv::LINE_AA);
	// Legend (top right).
	const int lx = 2 * pw - 260;
	cv::line(img, {lx, 14}, {lx + 30, 14}, kGtColour, 2, cv::LINE_AA);
	cv::putText(img, "ground truth", {lx + 36, 19}, cv::FONT_HERSHEY_SIMPLEX,
	            0.5, kTextColour, 1, cv::LINE_AA);
	cv::line(img, {lx, 32}, {lx + 30, 32}, kEstColour, 2, cv::LINE_AA);
	cv::putText(img, "estimate (aligned)", {lx + 36, 37},
	            cv::FONT_HERSHEY_SIMPLEX, 0.5, kTextColour, 1, cv::LINE_AA);
	return img;
}

cv::Mat imageStrip(const std::vector<cv::Mat>& images, double scale)
{
	if (images.empty()) throw std::invalid_argument("a strip of no image");
	if (!(scale > 0)) throw std::invalid_argument("strip scale must be > 0");
	std::vector<cv::Mat> row;
	for (const cv::Mat& m : images)
	{
		if (m.size() != images.front().size() ||
		    m.type() != images.front().type())
			throw std::invalid_argument("strip images differ in size or type");
		cv::Mat s;
		cv::resize(m, s, {}, scale, scale, cv::INTER_AREA);
		row.push_back(s);
	}
	cv::Mat out;
	cv::hconcat(row, out);
	return out;
}

void writePng(const std::string& path, const cv::Mat& img)
{
	writeImageFile(path, img);
}

}  // namespace bims::eval
