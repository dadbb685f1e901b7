#include <bims/common/config.h>
#include <bims/eval/association.h>
#include <bims/eval/mask_labels.h>
#include <mrpt/config/CConfigFile.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bims::eval
{
namespace fs = std::filesystem;

LabelConvention LabelConvention::explicitValues(int moving, int staticValue,
                                                const std::vector<int>& ignored)
{
	LabelConvention c;
	c.moving = moving < 0 ? 255 : moving;
	c.staticValue = staticValue < 0 ? 0 : staticValue;
	c.ignored = ignored;
	auto check = [](int v, const char* what)
	{
		if (v < 0 || v > 255)
			throw std::invalid_argument(std::string(what) + " value " +
			                            std::to_string(v) +
			                            " is outside 0-255");
	};
	check(c.moving, "moving");
	check(c.staticValue, "static");
	if (c.moving == c.staticValue)
		throw std::invalid_argument("moving and static are both " +
		                            std::to_string(c.moving));
	for (int v : c.ignored)
	{
		check(v, "not-scored");
		if (v == c.moving || v == c.staticValue)
			throw std::invalid_argument("value " + std::to_string(v) +
			                            " is both not scored and " +
			                            (v == c.moving ? "moving" : "static"));
	}
	return c;
}

LabelClass LabelConvention::classOf(int value) const
{
	if (isContract())
		return value >= 128 ? LabelClass::Moving : LabelClass::Static;
	if (value == moving) return LabelClass::Moving;
	if (value == staticValue) return LabelClass::Static;
	if (std::find(ignored.begin(), ignored.end(), value) != ignored.end())
		return LabelClass::NotScored;
	return LabelClass::Unknown;
}

std::string LabelConvention::describe() const
{
	if (isContract()) return "moving >= 128, static < 128";
	std::string s = "moving " + std::to_string(moving) + ", static " +
	                std::to_string(staticValue);
	if (!ignored.empty())
	{
		s += ", not scored";
		for (int v : ignored) s += " " + std::to_string(v);
	}
	return s;
}

void LabelConvention::toContract(const cv::Mat& labels, cv::Mat& moving,
                                 cv::Mat& scored) const
{
	cv::Mat lutMoving(1, 256, CV_8UC1), lutScored(1, 256, CV_8UC1);
	for (int i = 0; i < 256; i++)
	{
		const LabelClass c = classOf(i);
		lutMoving.at<uint8_t>(i) = c == LabelClass::Moving ? 255 : 0;
		lutScored.at<uint8_t>(i) =
		    c == LabelClass::Moving || c == LabelClass::Static ? 255 : 0;
	}
	// (new buffers: \a moving may share \a labels' pixels)
	cv::Mat m, s;
	cv::LUT(labels, lutMoving, m);
	cv::LUT(labels, lutScored, s);
	moving = m;
	scored = s;
}

std::vector<int> parseLabelValues(const std::string& text)
{
	std::string t = text;
	std::replace(t.begin(), t.end(), ',', ' ');
	std::istringstream in(t);
	std::vector<int> out;
	std::string item;
	while (in >> item)
	{
		size_t used = 0;
		int v = -1;
		try
		{
			v = std::stoi(item, &used);
		}
		catch (const std::exception&)
		{
			used = 0;
		}
		if (used != item.size() || v < 0 || v > 255)
			throw std::invalid_argument("'" + item +
			                            "' is not a label value 0-255");
		out.push_back(v);
	}
	return out;
}

std::optional<LabelConvention> readLabelConventionFile(const std::string& dir)
{
	const std::string path = (fs::path(dir) / kLabelConventionFile).string();
	if (!fs::exists(path)) return std::nullopt;
	const auto cfg = openIniFile(path);
	checkSections(*cfg, {"labels"});
	ConfigSection s(*cfg, "labels", true);
	const int moving = static_cast<int>(s.requireInt("moving", 0, 255));
	const int staticValue = static_cast<int>(s.requireInt("static", 0, 255));
	const std::string notScored = s.getString("not_scored", "");
	s.finish();
	try
	{
		return LabelConvention::explicitValues(moving, staticValue,
		                                       parseLabelValues(notScored));
	}
	catch (const std::invalid_argument& e)
	{
		s.fail("not_scored", e.what());
	}
}

void LabelValueCounts::add(const cv::Mat& labels)
{
	if (labels.type() != CV_8UC1)
		throw std::invalid_argument("a label image is 8-bit single-channel");
	std::array<uint64_t, 256> n{};
	for (int v = 0; v < labels.rows; v++)
	{
		const uint8_t* row = labels.ptr<uint8_t>(v);
		for (int u = 0; u < labels.cols; u++) n[row[u]]++;
	}
	for (int i = 0; i < 256; i++)
		if (n[i])
		{
			if (!pixels[i]) firstImage[i] = nImages;
			pixels[i] += n[i];
			images[i]++;
		}
	nImages++;
}

std::vector<int> LabelValueCounts::unknown(const LabelConvention& c) const
{
	std::vector<int> out;
	for (int i = 0; i < 256; i++)
		if (pixels[i] && c.classOf(i) == LabelClass::Unknown) out.push_back(i);
	return out;
}

std::string LabelValueCounts::describe(const LabelConvention& c) const
{
	std::string s;
	for (int i = 0; i < 256; i++)
	{
		if (!pixels[i]) continue;
		const LabelClass k = c.classOf(i);
		s += std::string(s.empty() ? "" : ", ") + std::to_string(i) + ": " +
		     std::to_string(pixels[i]) + " px in " + std::to_string(images[i]) +
		     " of " + std::to_string(nImages) + " labels (" +
		     (k == LabelClass::Moving      ? "moving"
		      : k == LabelClass::Static    ? "static"
		      : k == LabelClass::NotScored ? "not scored"
		                                   : "UNKNOWN") +
		     ")";
	}
	return s;
}

namespace
{
bool allDigits(const std::string& s)
{
	return !s.empty() &&
	       std::all_of(s.begin(), s.end(),
	                   [](unsigned char c) { return std::isdigit(c); });
}
}  // namespace

std::vector<MaskFile> listMaskFiles(const std::string& dir)
{
	if (!fs::is_directory(dir))
		throw std::runtime_error(dir + ": mask directory not found");
	std::vector<MaskFile> out;
	for (const auto& e : fs::directory_iterator(dir))
	{
		const auto p = e.path();
		if (p.extension() != ".png") continue;
		const std::string stem = p.stem().string();
		MaskFile f;
		f.name = p.filename().string();
		const size_t dot = stem.find('.');
		if (allDigits(stem))
			f.index = std::stol(stem);
		else if (dot != std::string::npos && allDigits(stem.substr(0, dot)) &&
		         allDigits(stem.substr(dot + 1)))
			f.stamp = std::stod(stem);
		else
			throw std::runtime_error(
			    dir + "/" + f.name +
			    ": a mask is named NNNNNN.png (scan index) or SECONDS.png "
			    "(timestamp)");
		if (!out.empty() && out.front().byTime() != f.byTime())
			throw std::runtime_error(dir + "/" + f.name + ": named by " +
			                         (f.byTime() ? "time" : "index") + " but " +
			                         out.front().name + " by " +
			                         (f.byTime() ? "index" : "time") +
			                         ": one folder, one naming");
		out.push_back(std::move(f));
	}
	if (out.empty())
		throw std::runtime_error(
		    dir + ": no masks (NNNNNN.png or SECONDS.png) in it");
	std::sort(out.begin(), out.end(),
	          [](const MaskFile& a, const MaskFile& b)
	          { return a.byTime() ? a.stamp < b.stamp : a.index < b.index; });
	return out;
}

std::map<long, double> readFrameStamps(const std::string& csvPath)
{
	std::ifstream in(csvPath);
	if (!in)
		throw std::runtime_error(csvPath +
		                         ": cannot open (the run's frames.csv)");
	std::string line;
	if (!std::getline(in, line)) throw std::runtime_error(csvPath + ": empty");
	std::vector<std::string> cols;
	{
		std::istringstream h(line);
		std::string c;
		while (std::getline(h, c, ',')) cols.push_back(c);
	}
	const auto col = [&](const char* name)
	{
		const auto it = std::find(cols.begin(), cols.end(), name);
		if (it == cols.end())
			throw std::runtime_error(csvPath + ":1: no column '" + name +
			                         "' in the header");
		return static_cast<size_t>(it - cols.begin());
	};
	const size_t ci = col("index"), ct = col("t");
	std::map<long, double> out;
	for (int n = 2; std::getline(in, line); n++)
	{
		if (line.empty()) continue;
		std::vector<std::string> f;
		std::istringstream r(line);
		std::string c;
		while (std::getline(r, c, ',')) f.push_back(c);
		long index = -1;
		double t = NAN;
		try
		{
			if (f.size() > std::max(ci, ct))
			{
				size_t a = 0, b = 0;
				index = std::stol(f[ci], &a);
				t = std::stod(f[ct], &b);
				if (a != f[ci].size() || b != f[ct].size()) index = -1;
			}
		}
		catch (const std::exception&)
		{
			index = -1;
		}
		if (index < 0 || !std::isfinite(t))
			throw std::runtime_error(csvPath + ":" + std::to_string(n) +
			                         ": expected an index and a time stamp");
		if (!out.emplace(index, t).second)
			throw std::runtime_error(csvPath + ":" + std::to_string(n) +
			                         ": index " + std::to_string(index) +
			                         " twice");
	}
	return out;
}

namespace
{
/** matchMasks() by scan index: a label and the prediction of its index. */
MaskMatch matchMasksByIndex(const std::vector<MaskFile>& labels,
                            const std::vector<MaskFile>& preds)
{
	MaskMatch m;
	size_t j = 0;
	for (const MaskFile& l : labels)
	{
		while (j < preds.size() && preds[j].index < l.index) ++j;
		if (j < preds.size() && preds[j].index == l.index)
			m.pairs.push_back({&l, &preds[j], 0});
		else
		{
			m.labelsWithoutPrediction.push_back(&l);
			if (l.index < preds.front().index || l.index > preds.back().index)
				m.labelsOutsidePredictions.push_back(&l);
		}
	}
	// predictions without the label of their index: inside the labels'
	// span a missing label, outside it a longer run
	size_t i = 0;
	for (const MaskFile& p : preds)
	{
		while (i < labels.size() && labels[i].index < p.index) ++i;
		if (i < labels.size() && labels[i].index == p.index) continue;
		if (p.index < labels.front().index || p.index > labels.back().index)
			++m.predictionsOutside;
		else
			m.predictionsWithoutLabel.push_back(&p);
	}
	return m;
}

/** The predictions in time order (their own stamps, or the run's for those
 * named by scan index) and their stamps. */
void predictionsByTime(const std::vector<MaskFile>& preds,
                       const std::map<long, double>& predStamps,
                       std::vector<const MaskFile*>& sorted,
                       std::vector<double>& stamps)
{
	std::vector<const MaskFile*> ps;
	std::vector<double> tp;
	for (const MaskFile& p : preds)
	{
		double t = p.stamp;
		if (!p.byTime())
		{
			const auto it = predStamps.find(p.index);
			if (it == predStamps.end())
				throw std::runtime_error(p.name + ": no time stamp for scan " +
				                         std::to_string(p.index) +
				                         " in the run's frames.csv");
			t = it->second;
		}
		ps.push_back(&p);
		tp.push_back(t);
	}
	std::vector<size_t> order(ps.size());
	for (size_t i = 0; i < order.size(); i++) order[i] = i;
	std::sort(order.begin(), order.end(),
	          [&tp](size_t a, size_t b) { return tp[a] < tp[b]; });
	for (size_t i : order)
	{
		sorted.push_back(ps[i]);
		stamps.push_back(tp[i]);
	}
}
}  // namespace

MaskMatch matchMasks(const std::vector<MaskFile>& labels,
                     const std::vector<MaskFile>& preds,
                     const std::map<long, double>& predStamps, double maxDt)
{
	if (labels.empty() || preds.empty()) return {};
	const bool byTime = labels.front().byTime();
	if (!byTime && preds.front().byTime())
		throw std::runtime_error(
		    "labels are named by scan index, predictions by time: name both "
		    "the same way");
	if (!byTime) return matchMasksByIndex(labels, preds);
	// time stamps of both sides, sorted (the files are)
	MaskMatch m;
	std::vector<double> tl, tps;
	for (const MaskFile& l : labels) tl.push_back(l.stamp);
	std::vector<const MaskFile*> ps;
	predictionsByTime(preds, predStamps, ps, tps);
	const IndexPairs pairs = associateGreedy(tl, tps, maxDt);
	std::vector<bool> labelUsed(tl.size()), predUsed(tps.size());
	for (const auto& [i, j] : pairs)
	{
		m.pairs.push_back({&labels[i], ps[j], std::abs(tl[i] - tps[j])});
		labelUsed[i] = predUsed[j] = true;
	}
	for (size_t i = 0; i < tl.size(); i++)
	{
		if (labelUsed[i]) continue;
		m.labelsWithoutPrediction.push_back(&labels[i]);
		if (tl[i] < tps.front() - maxDt || tl[i] > tps.back() + maxDt)
			m.labelsOutsidePredictions.push_back(&labels[i]);
	}
	for (size_t j = 0; j < tps.size(); j++)
	{
		if (predUsed[j]) continue;
		if (tps[j] < tl.front() - maxDt || tps[j] > tl.back() + maxDt)
			++m.predictionsOutside;
		else
			m.predictionsWithoutLabel.push_back(ps[j]);
	}
	return m;
}

}  // namespace bims::eval
