#include <bims/eval/plots.h>
#include <bims/io/output_paths.h>

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

namespace
{
const cv::Scalar kGridColour(225, 225, 225), kMissingColour(0, 0, 200);
const int kFont = cv::FONT_HERSHEY_SIMPLEX;

/** Series colours (BGR), as the usual categorical palettes. */
cv::Scalar seriesColour(size_t i)
{
	static const cv::Scalar c[] = {
	    {180, 119, 31},  {14, 127, 255}, {44, 160, 44},   {40, 39, 214},
	    {189, 103, 148}, {75, 86, 140},  {194, 119, 227}, {127, 127, 127},
	    {34, 189, 188},  {207, 190, 23}};
	return c[i % (sizeof(c) / sizeof(c[0]))];
}

int textWidth(const std::string& t, double scale)
{
	int base = 0;
	return cv::getTextSize(t, kFont, scale, 1, &base).width;
}

std::vector<std::string> lines(const std::string& text)
{
	std::vector<std::string> out;
	size_t b = 0;
	for (size_t e; (e = text.find('\n', b)) != std::string::npos; b = e + 1)
		out.push_back(text.substr(b, e - b));
	out.push_back(text.substr(b));
	return out;
}

void putLabel(cv::Mat& img, const std::string& t, cv::Point at, double scale)
{
	cv::putText(img, t, at, kFont, scale, kTextColour, 1, cv::LINE_AA);
}
}  // namespace

namespace
{
constexpr double kBarLabelScale = 0.45, kBarValueScale = 0.38;
constexpr int kBarMin = 28, kBarMax = 64, kGroupGap = 24, kBarsLeft = 96,
              kBarsRight = 30, kBarsHeight = 640, kBarsMinWidth = 1024;

/** The horizontal layout of a bar chart: each group as wide as its bars or
 * its longest label line, whichever is wider, stretched to the width. */
struct BarLayout
{
	std::vector<int> natural;  ///< each group's width before stretching
	size_t labelLines = 1;     ///< of the longest group label
	int width = 0;             ///< of the image
	double stretch = 1;
	int barW = kBarMax;
};

BarLayout barLayout(const GroupedBars& c)
{
	const size_t nG = c.groups.size(), nS = c.series.size();
	BarLayout L;
	L.natural.resize(nG);
	for (size_t g = 0; g < nG; g++)
	{
		int w = static_cast<int>(std::max<size_t>(nS, 1)) * kBarMin;
		const auto ls = lines(c.groups[g]);
		L.labelLines = std::max(L.labelLines, ls.size());
		for (const auto& l : ls) w = std::max(w, textWidth(l, kBarLabelScale));
		L.natural[g] = w + kGroupGap;
	}
	int sum = 0;
	for (int w : L.natural) sum += w;
	L.width = std::max(kBarsMinWidth, kBarsLeft + kBarsRight + sum);
	L.stretch =
	    sum > 0 ? static_cast<double>(L.width - kBarsLeft - kBarsRight) / sum
	            : 1.0;
	for (size_t g = 0; g < nG; g++)
		L.barW = std::min(
		    L.barW, static_cast<int>((L.natural[g] * L.stretch - kGroupGap) /
		                             std::max<size_t>(nS, 1)));
	return L;
}

/** The legend: a row of swatches under the title, wrapped (and the mark of
 * a missing value when there is one). Returns the baseline of its last
 * row. */
int drawBarLegend(cv::Mat& img, const GroupedBars& c, int width)
{
	bool anyMissing = false;
	for (const auto& row : c.values)
		for (double v : row) anyMissing |= !std::isfinite(v);
	int lx = kBarsLeft, ly = 52;
	auto legendRoom = [&](const std::string& t)
	{
		const int w = 22 + textWidth(t, kBarLabelScale) + 20;
		if (lx + w > width - kBarsRight && lx > kBarsLeft)
			lx = kBarsLeft, ly += 22;
		return w;
	};
	for (size_t s = 0; s < c.series.size(); s++)
	{
		const int w = legendRoom(c.series[s]);
		cv::rectangle(img, {lx, ly - 12}, {lx + 14, ly + 2}, seriesColour(s),
		              cv::FILLED);
		putLabel(img, c.series[s], {lx + 22, ly}, kBarLabelScale);
		lx += w;
	}
	if (anyMissing)
	{
		const std::string& t = c.missingLabel;
		const int w = legendRoom(t);
		cv::line(img, {lx + 1, ly - 11}, {lx + 13, ly + 1}, kMissingColour, 2);
		cv::line(img, {lx + 1, ly + 1}, {lx + 13, ly - 11}, kMissingColour, 2);
		putLabel(img, t, {lx + 22, ly}, kBarLabelScale);
		lx += w;
	}
	return ly;
}

/** The plot area [top, bottom] and its value scale [lo, hi] in steps. */
struct ValueScale
{
	int top, bottom;
	double lo = 0, hi = 0, step = 1;
	/** The image row of value \a v. */
	int py(double v) const
	{
		return static_cast<int>(
		    std::lround(bottom - (v - lo) / (hi - lo) * (bottom - top)));
	}
};

ValueScale valueScale(const GroupedBars& c, int top, int bottom)
{
	ValueScale a{top, bottom};
	for (const auto& row : c.values)
		for (double v : row)
			if (std::isfinite(v))
				a.lo = std::min(a.lo, v), a.hi = std::max(a.hi, v);
	if (c.yMax && *c.yMax > a.lo) a.hi = std::max(a.hi, *c.yMax);
	if (!(a.hi > a.lo)) a.hi = a.lo + 1;
	a.step = niceLength((a.hi - a.lo) / 5);
	a.lo = std::floor(a.lo / a.step) * a.step;
	if (!(c.yMax && a.hi == *c.yMax))
		a.hi = std::ceil(a.hi * 1.06 / a.step) * a.step;  // room for labels
	return a;
}

/** The grid lines with their values, the axes, and the vertical axis'
 * name turned by 90 degrees. */
void drawValueAxis(cv::Mat& img, const GroupedBars& c, const ValueScale& a)
{
	const int width = img.cols;
	char txt[64];
	for (double t = a.lo; t <= a.hi + 0.5 * a.step; t += a.step)
	{
		const int y = a.py(t);
		cv::line(img, {kBarsLeft, y}, {width - kBarsRight, y}, kGridColour, 1);
		std::snprintf(txt, sizeof(txt), "%g", std::abs(t) < 1e-12 ? 0.0 : t);
		putLabel(img, txt,
		         {kBarsLeft - 8 - textWidth(txt, kBarLabelScale), y + 5},
		         kBarLabelScale);
	}
	cv::line(img, {kBarsLeft, a.top}, {kBarsLeft, a.bottom}, kTextColour, 1);
	cv::line(img, {kBarsLeft, a.py(0)}, {width - kBarsRight, a.py(0)},
	         kTextColour, 1);
	const int tw = textWidth(c.yLabel, 0.5) + 8;
	cv::Mat t(24, tw, CV_8UC3, cv::Scalar(255, 255, 255));
	cv::putText(t, c.yLabel, {4, 17}, kFont, 0.5, kTextColour, 1, cv::LINE_AA);
	cv::rotate(t, t, cv::ROTATE_90_COUNTERCLOCKWISE);
	const int y0 = std::max(0, (a.top + a.bottom) / 2 - t.rows / 2);
	const int h = std::min(t.rows, img.rows - y0);
	t(cv::Rect(0, 0, t.cols, h)).copyTo(img(cv::Rect(8, y0, t.cols, h)));
}

/** Group \a g's bars (a cross for a missing value), values and label,
 * centred at column \a cx. */
void drawBarGroup(cv::Mat& img, const GroupedBars& c, size_t g, int cx,
                  int barW, const ValueScale& a)
{
	const size_t nS = c.series.size();
	const int x0 = cx - static_cast<int>(nS) * barW / 2;
	char txt[64];
	for (size_t s = 0; s < nS; s++)
	{
		const int bx = x0 + static_cast<int>(s) * barW;
		const double v = c.values[g][s];
		if (!std::isfinite(v))
		{
			const int mx = bx + barW / 2, my = a.py(0) - 8;
			cv::line(img, {mx - 6, my - 6}, {mx + 6, my + 6}, kMissingColour,
			         2);
			cv::line(img, {mx - 6, my + 6}, {mx + 6, my - 6}, kMissingColour,
			         2);
			continue;
		}
		cv::rectangle(img, {bx + 2, a.py(v)}, {bx + barW - 2, a.py(0)},
		              seriesColour(s), cv::FILLED);
		std::snprintf(txt, sizeof(txt), "%.3g", v);
		putLabel(img, txt,
		         {bx + barW / 2 - textWidth(txt, kBarValueScale) / 2,
		          a.py(std::max(v, 0.0)) - 5},
		         kBarValueScale);
	}
	const auto ls = lines(c.groups[g]);
	for (size_t i = 0; i < ls.size(); i++)
		putLabel(img, ls[i],
		         {cx - textWidth(ls[i], kBarLabelScale) / 2,
		          a.bottom + 20 + 18 * static_cast<int>(i)},
		         kBarLabelScale);
}
}  // namespace

cv::Mat plotGroupedBars(const GroupedBars& c)
{
	const size_t nG = c.groups.size(), nS = c.series.size();
	if (c.values.size() != nG)
		throw std::invalid_argument("plotGroupedBars: one row per group");
	for (const auto& row : c.values)
		if (row.size() != nS)
			throw std::invalid_argument(
			    "plotGroupedBars: one value per series in each group");
	const BarLayout L = barLayout(c);
	const int width = L.width;
	cv::Mat img(kBarsHeight, width, CV_8UC3, cv::Scalar(255, 255, 255));
	putLabel(img, c.title, {12, 28}, 0.65);
	const int ly = drawBarLegend(img, c, width);
	const ValueScale a =
	    valueScale(c, ly + 30,
	               kBarsHeight - 16 - 18 * static_cast<int>(L.labelLines) - 36);
	drawValueAxis(img, c, a);
	double x = kBarsLeft;
	for (size_t g = 0; g < nG; g++)
	{
		const double gw = L.natural[g] * L.stretch;
		drawBarGroup(img, c, g, static_cast<int>(std::lround(x + gw / 2)),
		             L.barW, a);
		x += gw;
	}
	putLabel(img, c.xLabel,
	         {kBarsLeft + (width - kBarsLeft - kBarsRight) / 2 -
	              textWidth(c.xLabel, 0.5) / 2,
	          kBarsHeight - 14},
	         0.5);
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
