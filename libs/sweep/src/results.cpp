#include <bims/eval/plots.h>
#include <bims/io/json.h>
#include <bims/io/output_paths.h>
#include <bims/sweep/results.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>

namespace fs = std::filesystem;

namespace bims::sweep
{
namespace
{
const double kNaN = std::numeric_limits<double>::quiet_NaN();

/** The numbers of \a j by path: objects descended, arrays left out. */
void flatten(const Json& j, const std::string& path,
             std::vector<std::pair<std::string, double>>& out)
{
	if (j.is_object())
		for (const auto& [k, v] : j.items())
			flatten(v, path.empty() ? k : path + "." + k, out);
	else if (j.is_number())
		out.emplace_back(path, j.get<double>());
	else if (j.is_null() && !path.empty())
		out.emplace_back(path, kNaN);
}

/** "" for NaN; whole numbers without decimals; else \a digits significant
 * digits. */
std::string number(double v, int digits)
{
	if (!std::isfinite(v)) return "";
	char b[64];
	if (v == std::round(v) && std::abs(v) < 1e15)
		std::snprintf(b, sizeof(b), "%.0f", v);
	else
		std::snprintf(b, sizeof(b), "%.*g", digits, v);
	return b;
}

std::string csvCell(const std::string& s)
{
	if (s.find_first_of(",\"\r\n") == std::string::npos &&
	    (s.empty() || (s.front() != ' ' && s.back() != ' ')))
		return s;
	std::string q = "\"";
	for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
	return q + "\"";
}

std::string mdCell(const std::string& s)
{
	std::string out;
	for (char c : s)
		out += c == '|' ? std::string("\\|")
		                : std::string(1, c == '\n' || c == '\r' ? ' ' : c);
	return out;
}

bool isScore(const std::string& name)
{
	const std::string leaf = name.substr(name.rfind('.') + 1);
	return leaf == "rmse" || leaf == "f1" || leaf == "iou" ||
	       leaf == "precision" || leaf == "recall";
}

/** The legend's name of each file: its stem ("pendulum_slow" for
 * "../rawlogs/pendulum_slow.rawlog"), or the path as written when two
 * files share a stem. */
std::map<std::string, std::string> legendNames(
    const std::set<std::string>& written)
{
	std::map<std::string, std::string> name;
	std::map<std::string, int> uses;
	for (const auto& w : written) uses[fs::path(w).stem().string()]++;
	for (const auto& w : written)
	{
		const std::string stem = fs::path(w).stem().string();
		name[w] = uses[stem] > 1 || stem.empty() ? w : stem;
	}
	return name;
}

/** A readable name for the plot's vertical axis. */
std::string axisName(const std::string& metric)
{
	static const std::map<std::string, std::string> known = {
	    {"fps", "fps: frames/s end to end"},
	    {"wall_seconds", "wall_seconds: s per run"},
	    {"cpu_seconds", "cpu_seconds: CPU s per run"},
	    {"peak_resident_mib", "peak_resident_mib: MiB"}};
	const auto it = known.find(metric);
	if (it != known.end()) return it->second;
	return metric.rfind("stage_ms.", 0) == 0 ? metric + " (ms per frame)"
	                                         : metric;
}
}  // namespace

double RunResult::metric(const std::string& name) const
{
	for (const auto& [k, v] : metrics)
		if (k == name) return v;
	return kNaN;
}

RunResult collectRun(const RunSpec& run, const std::string& outDir,
                     const JobOutcome* outcome)
{
	RunResult r;
	r.run = run;
	r.run.configText.clear();
	if (outcome && outcome->started)
	{
		r.exitCode = outcome->exitCode;
		r.seconds = outcome->seconds;
	}
	const std::string dir = runDir(outDir, run.id);
	const std::string mpath = runOutDir(outDir, run.id) + "/metrics.json";
	std::error_code ec;
	if (!fs::exists(mpath, ec))
	{
		r.status = !outcome           ? "missing"
		           : outcome->started ? "failed"
		                              : "not run";
		if (outcome && outcome->started)
			r.error = "no metrics.json (exit code " +
			          std::to_string(outcome->exitCode) + "; see " + dir +
			          "/log.txt)";
		return r;
	}
	try
	{
		const Json m = readJsonFile(mpath);
		r.status = m.value("status", std::string("?"));
		r.error = m.value("error", std::string());
		flatten(m, "", r.metrics);
	}
	catch (const std::exception& e)
	{
		r.status = "failed";
		r.error = e.what();
		return r;
	}
	std::vector<fs::path> more;
	for (const auto& e : fs::directory_iterator(dir, ec))
		if (e.path().extension() == ".json" && e.is_regular_file(ec))
			more.push_back(e.path());
	std::sort(more.begin(), more.end());
	for (const auto& p : more)
	{
		try
		{
			flatten(readJsonFile(p.string()), p.stem().string(), r.metrics);
		}
		catch (const std::exception& e)
		{
			r.error += (r.error.empty() ? "" : "; ") + std::string(e.what());
		}
	}
	return r;
}

std::vector<std::string> ResultTable::metricNames() const
{
	std::vector<std::string> names;
	std::set<std::string> seen;
	for (const auto& r : rows)
		for (const auto& [k, v] : r.metrics)
			if (seen.insert(k).second) names.push_back(k);
	return names;
}

size_t ResultTable::failures() const
{
	size_t n = 0;
	for (const auto& r : rows) n += !r.ok();
	return n;
}

namespace
{
/** One run's cells of the results table: id, config, rawlog, the override
 * values, the \a constants' values, status, exit code, seconds and \a
 * metrics (with these digits). */
std::vector<std::string> rowCells(
    const RunResult& r,
    const std::vector<std::pair<std::string, std::string>>& constants,
    const std::vector<std::string>& metrics, int secondsDigits,
    int metricDigits)
{
	std::vector<std::string> c = {r.run.id, r.run.config.written,
	                              r.run.rawlog.written};
	for (const auto& [k, v] : r.run.overrides) c.push_back(v);
	for (const auto& [k, v] : constants) c.push_back(v);
	c.push_back(r.status);
	c.push_back(r.exitCode ? std::to_string(*r.exitCode) : "");
	c.push_back(r.seconds ? number(*r.seconds, secondsDigits) : "");
	for (const auto& m : metrics)
		c.push_back(number(r.metric(m), metricDigits));
	return c;
}
}  // namespace

std::string csvText(const ResultTable& t)
{
	const auto metrics = t.metricNames();
	std::vector<std::string> head = {"id", "config", "rawlog"};
	head.insert(head.end(), t.plan.gridKeys.begin(), t.plan.gridKeys.end());
	for (const auto& [k, v] : t.plan.constants) head.push_back(k);
	head.insert(head.end(), {"status", "exit_code", "run_seconds"});
	head.insert(head.end(), metrics.begin(), metrics.end());
	head.push_back("error");
	std::string out;
	auto line = [&](const std::vector<std::string>& cells)
	{
		for (size_t i = 0; i < cells.size(); i++)
			out += (i ? "," : "") + csvCell(cells[i]);
		out += "\n";
	};
	line(head);
	for (const auto& r : t.rows)
	{
		auto c = rowCells(r, t.plan.constants, metrics, 4, 9);
		c.push_back(r.error);
		line(c);
	}
	return out;
}

std::string markdownText(const ResultTable& t, const std::string& plotMetric)
{
	std::vector<std::string> metrics;
	const auto all = t.metricNames();
	auto add = [&](const std::string& m)
	{
		if (std::find(all.begin(), all.end(), m) != all.end() &&
		    std::find(metrics.begin(), metrics.end(), m) == metrics.end())
			metrics.push_back(m);
	};
	for (const char* m :
	     {"frames_processed", "fps", "wall_seconds", "cpu_seconds",
	      "peak_resident_mib", "stage_ms.total.median"})
		add(m);
	add(plotMetric);
	// the scores some run has a value of (a score no run has, e.g. the
	// figures of frames without moving labels, is only in results.csv)
	for (const auto& m : all)
		if (isScore(m) && std::any_of(t.rows.begin(), t.rows.end(),
		                              [&](const RunResult& r)
		                              { return std::isfinite(r.metric(m)); }))
			add(m);

	std::string out = "# Sweep " + mdCell(t.plan.name) + "\n\n";
	out += std::to_string(t.rows.size()) + " runs, " +
	       std::to_string(t.rows.size() - t.failures()) + " ok, " +
	       std::to_string(t.failures()) + " not (from " +
	       mdCell(t.plan.sweepFile) +
	       (t.plan.frames.empty() ? "" : ", frames " + t.plan.frames) +
	       "). Every column in results.csv, " + mdCell(plotMetric) +
	       " per run in results.png.\n\n";
	if (!t.plan.constants.empty())
		out += "Every run: " + mdCell(constantsText(t.plan)) + ".\n\n";
	std::vector<std::string> head = {"id", "config", "rawlog"};
	head.insert(head.end(), t.plan.gridKeys.begin(), t.plan.gridKeys.end());
	head.insert(head.end(), {"status", "exit", "s"});
	head.insert(head.end(), metrics.begin(), metrics.end());
	std::string rule;
	for (const auto& h : head)
	{
		out += "| " + mdCell(h) + " ";
		rule += "|---";
	}
	out += "|\n" + rule + "|\n";
	for (const auto& r : t.rows)
	{
		for (const auto& x : rowCells(r, {}, metrics, 3, 4))
			out += "| " + mdCell(x) + " ";
		out += "|\n";
	}
	if (t.failures())
	{
		out += "\n## Runs not ok\n\n";
		for (const auto& r : t.rows)
			if (!r.ok())
				out += "- " + mdCell(r.run.id) + ": " + r.status +
				       (r.exitCode ? ", exit " + std::to_string(*r.exitCode)
				                   : "") +
				       (r.error.empty() ? "" : ": " + mdCell(r.error)) + "\n";
	}
	return out;
}

eval::GroupedBars resultsChart(const ResultTable& t, const std::string& metric)
{
	const auto all = t.metricNames();
	if (!all.empty() && std::find(all.begin(), all.end(), metric) == all.end())
	{
		std::string list;
		for (const auto& m : all)
			if (m.find("stage_ms.") != 0 ||
			    m.find(".median") != std::string::npos)
				list += (list.empty() ? "" : ", ") + m;
		throw std::invalid_argument("no run has the metric '" + metric +
		                            "' (some there are: " + list + ")");
	}
	eval::GroupedBars c;
	c.title = t.plan.name + ": " + metric + " per run";
	c.yLabel = axisName(metric);
	c.xLabel =
	    t.plan.gridKeys.empty() ? "(no [grid] overrides)" : "[grid] overrides";
	if (!t.plan.constants.empty())
		c.xLabel += "; every run: " + constantsText(t.plan);
	c.missingLabel = "no value (run not ok)";
	c.yMax = metricAxisTop(metric);
	const auto shortKeys = shortGridKeys(t.plan.gridKeys);
	std::set<std::string> configs, rawlogs;
	for (const auto& r : t.rows)
	{
		configs.insert(r.run.config.written);
		rawlogs.insert(r.run.rawlog.written);
	}
	const auto configName = legendNames(configs);
	const auto rawlogName = legendNames(rawlogs);
	// each row's group (its grid values) and series (config, rawlog)
	std::map<std::string, size_t> group, series;
	std::vector<std::pair<size_t, size_t>> cell;
	for (const auto& r : t.rows)
	{
		std::string g;
		for (size_t i = 0; i < r.run.overrides.size(); i++)
			g += (i ? "\n" : "") + shortKeys[i] + "=" +
			     r.run.overrides[i].second;
		std::string s =
		    configs.size() > 1 ? configName.at(r.run.config.written) : "";
		if (rawlogs.size() > 1 || s.empty())
			s += (s.empty() ? "" : ", ") + rawlogName.at(r.run.rawlog.written);
		if (group.emplace(g, c.groups.size()).second) c.groups.push_back(g);
		if (series.emplace(s, c.series.size()).second) c.series.push_back(s);
		cell.emplace_back(group[g], series[s]);
	}
	c.values.assign(c.groups.size(),
	                std::vector<double>(c.series.size(), kNaN));
	for (size_t i = 0; i < t.rows.size(); i++)
		if (t.rows[i].ok())
			c.values[cell[i].first][cell[i].second] = t.rows[i].metric(metric);
	return c;
}

std::optional<double> metricAxisTop(const std::string& metric)
{
	const std::string last = metric.substr(metric.rfind('.') + 1);
	const auto endsWith = [&](const char* e)
	{
		const std::string x(e);
		return last.size() >= x.size() &&
		       last.compare(last.size() - x.size(), x.size(), x) == 0;
	};
	for (const char* score : {"f1", "precision", "recall", "iou"})
		if (last == score) return 1.0;
	if (endsWith("_fraction")) return 1.0;
	return std::nullopt;
}

cv::Mat plotResults(const ResultTable& t, const std::string& metric)
{
	return eval::plotGroupedBars(resultsChart(t, metric));
}

void writeResults(const ResultTable& t, const std::string& outDir,
                  const std::string& plotMetric)
{
	writeFileAtomically(outDir + "/results.csv", csvText(t));
	writeFileAtomically(outDir + "/results.md", markdownText(t, plotMetric));
	writeImageFile(outDir + "/results.png", plotResults(t, plotMetric));
}

}  // namespace bims::sweep
