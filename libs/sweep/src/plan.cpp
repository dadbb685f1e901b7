#include <bims/common/config.h>
#include <bims/io/output_paths.h>
#include <bims/pipeline/config.h>
#include <bims/pipeline/run.h>
#include <bims/sweep/plan.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/vector_loadsave.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>

namespace fs = std::filesystem;

namespace bims::sweep
{
namespace
{
/** The files of a [sweep] list, resolved against \a folder; each present
 * and listed once. */
std::vector<ListedFile> listedFiles(ConfigSection& s, const std::string& key,
                                    const fs::path& folder)
{
	std::vector<ListedFile> out;
	std::set<std::string> seen;
	for (const auto& w : s.getWords(key))
	{
		const fs::path p = fs::path(w).is_absolute() ? fs::path(w) : folder / w;
		ListedFile f{w, fs::absolute(p).lexically_normal().string()};
		std::error_code ec;
		if (!fs::is_regular_file(f.path, ec))
			s.fail(key, "'" + w + "': " +
			                (fs::exists(f.path, ec) ? "not a regular file ("
			                                        : "no such file (") +
			                f.path + ")");
		if (!seen.insert(f.path).second)
			s.fail(key, "'" + w + "' listed twice");
		out.push_back(std::move(f));
	}
	if (out.empty()) s.fail(key, "required: one or more files");
	return out;
}

/** A part of a run's name: letters, digits and . _ = + - only (others
 * become -), at most 24 characters. */
std::string idPart(const std::string& s)
{
	std::string out;
	for (char c : s.substr(0, 24))
		out += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' ||
		        c == '_' || c == '=' || c == '+' || c == '-')
		           ? c
		           : '-';
	return out;
}

std::string stem(const std::string& path)
{
	return fs::path(path).stem().string();
}

/** Reads \a text with bims-run's loader; a failure becomes a ConfigError
 * that starts with \a where (the loader names its source "<memory>"). */
void checkWithLoader(const std::string& text, const std::string& where)
{
	try
	{
		mrpt::config::CConfigFileMemory mem(text);
		pipeline::ExperimentConfig cfg;
		cfg.loadFromConfigFile(mem);
	}
	catch (const std::exception& e)
	{
		std::string what = e.what();
		const std::string memory =
		    configSourceName(mrpt::config::CConfigFileMemory()) + ": ";
		if (what.rfind(memory, 0) == 0) what = what.substr(memory.size());
		throw ConfigError(where + ": " + what);
	}
}

/** \a base with the overrides set. */
std::string derive(
    const std::string& base, const std::vector<GridAxis>& grid,
    const std::vector<std::pair<std::string, std::string>>& overrides)
{
	mrpt::config::CConfigFileMemory mem(base);
	for (size_t i = 0; i < grid.size(); i++)
		mem.write(grid[i].section, grid[i].key, overrides[i].second);
	return mem.getContent();
}

/** The keys of \a s's section (none when it is absent). */
std::vector<std::string> keysOf(const mrpt::config::CConfigFileBase& cfg,
                                const ConfigSection& s)
{
	std::vector<std::string> keys;
	if (s.exists()) cfg.getAllKeys(s.name(), keys);
	return keys;
}

/** \a k as an experiment key "section.key" (no values yet). */
GridAxis experimentKey(const ConfigSection& s, const std::string& k)
{
	GridAxis a;
	a.name = k;
	const auto dot = k.find('.');
	if (dot == std::string::npos || dot == 0 || dot + 1 == k.size() ||
	    k.find('.', dot + 1) != std::string::npos)
		s.fail(k,
		       "not an experiment key: write section.key (e.g. "
		       "grids.voxel_size)");
	a.section = k.substr(0, dot);
	a.key = k.substr(dot + 1);
	return a;
}

/** [truth] masks or trajectory: "auto" (each rawlog's RAWLOG_gt/masks or
 * RAWLOG_gt/groundtruth.txt, the simulator's), or one path per rawlog
 * (relative ones against SWEEP.ini's folder); each present. One "" per
 * rawlog when absent. */
std::vector<std::string> truthPaths(ConfigSection& t, const std::string& key,
                                    const std::vector<ListedFile>& rawlogs,
                                    const fs::path& folder)
{
	const bool folders = key == "masks";
	const auto words = t.getWords(key);
	std::vector<std::string> out(rawlogs.size());
	if (words.empty()) return out;
	const bool autoPaths = words.size() == 1 && words[0] == "auto";
	if (!autoPaths && words.size() != rawlogs.size())
		t.fail(key, "'auto' or one path per rawlog (" +
		                std::to_string(rawlogs.size()) + "), not " +
		                std::to_string(words.size()));
	for (size_t i = 0; i < rawlogs.size(); i++)
	{
		const std::string& w = autoPaths ? "" : words[i];
		const fs::path p = autoPaths
		                       ? fs::path(groundTruthDirFor(rawlogs[i].path)) /
		                             (folders ? "masks" : "groundtruth.txt")
		                   : fs::path(w).is_absolute() ? fs::path(w)
		                                               : folder / w;
		out[i] = fs::absolute(p).lexically_normal().string();
		std::error_code ec;
		if (folders ? !fs::is_directory(out[i], ec)
		            : !fs::is_regular_file(out[i], ec))
			t.fail(key, (autoPaths ? "auto: " + rawlogs[i].written + "'s "
			                       : "'" + w + "': ") +
			                "no such " + (folders ? "folder" : "file") + " (" +
			                out[i] + ")");
	}
	return out;
}
}  // namespace

SweepSpec SweepSpec::load(const std::string& path)
{
	const auto file = openIniFile(path);
	const mrpt::config::CConfigFile& cfg = *file;
	checkSections(cfg, {"sweep", "grid", "set", "truth"});
	SweepSpec spec;
	spec.file = path;
	const fs::path folder = fs::path(path).parent_path();
	ConfigSection s(cfg, "sweep", true);
	spec.configs = listedFiles(s, "configs", folder);
	spec.rawlogs = listedFiles(s, "rawlogs", folder);
	spec.frames = s.getString("frames", "");
	if (!spec.frames.empty())
	{
		try
		{
			pipeline::FrameRange::parse(spec.frames);
		}
		catch (const std::invalid_argument& e)
		{
			s.fail("frames", e.what());
		}
	}
	spec.name = s.getString("name", stem(path));
	s.finish();

	ConfigSection g(cfg, "grid");
	for (const auto& k : keysOf(cfg, g))
	{
		GridAxis a = experimentKey(g, k);
		a.values = g.getList(k);
		if (a.values.empty()) g.fail(k, "no value");
		std::set<std::string> seen;
		for (const auto& v : a.values)
			if (!seen.insert(v).second)
				g.fail(k, "value '" + v + "' given twice");
		// one value: the same for every run, named once, not in run ids
		a.from = "grid";
		(a.values.size() > 1 ? spec.grid : spec.constants)
		    .push_back(std::move(a));
	}
	g.finish();

	ConfigSection c(cfg, "set");
	for (const auto& k : keysOf(cfg, c))
	{
		GridAxis a = experimentKey(c, k);
		if (g.has(k)) c.fail(k, "also in [grid]: give it in one of them");
		a.values = {c.getString(k, "")};
		a.from = "set";
		if (a.values[0].empty()) c.fail(k, "no value");
		spec.constants.push_back(std::move(a));
	}
	c.finish();
	std::sort(spec.constants.begin(), spec.constants.end(),
	          [](const GridAxis& a, const GridAxis& b)
	          { return a.name < b.name; });

	ConfigSection t(cfg, "truth");
	spec.truth.masks = truthPaths(t, "masks", spec.rawlogs, folder);
	spec.truth.trajectories = truthPaths(t, "trajectory", spec.rawlogs, folder);
	spec.truth.movingValue = t.getInt("moving_value", -1, 0, 255);
	spec.truth.staticValue = t.getInt("static_value", -1, 0, 255);
	spec.truth.ignoreValues = t.getString("ignore_values", "");
	spec.truth.depthValid = t.getBool("depth_valid", true);
	if (t.exists() && !spec.truth.any())
		t.fail("masks", "required: masks, trajectory or both");
	t.finish();
	return spec;
}

bool TruthSpec::any() const
{
	for (const auto* l : {&masks, &trajectories})
		for (const auto& p : *l)
			if (!p.empty()) return true;
	return false;
}

namespace
{
using Overrides = std::vector<std::pair<std::string, std::string>>;

/** The base of every run of \a config: its text with the constants set,
 * each constant checked alone, then all, then each grid value alone (the
 * error names the key and the value). */
std::string checkedBase(const SweepSpec& spec, const SweepPlan& plan,
                        const ListedFile& config)
{
	checkIniFile(config.path);
	std::string base = mrpt::io::file_get_contents(config.path);
	checkWithLoader(base, config.path);
	for (const auto& a : spec.constants)
		checkWithLoader(derive(base, {a}, {{a.name, a.values[0]}}),
		                spec.file + ": [" + a.from + "] " + a.name + " = " +
		                    a.values[0] + ": on " + config.written);
	Overrides constants;
	for (const auto& a : spec.constants)
		constants.emplace_back(a.name, a.values[0]);
	base = derive(base, spec.constants, constants);
	if (constants.size() > 1)
		checkWithLoader(base, spec.file + ": " + constantsText(plan) + ": on " +
		                          config.written);
	for (const auto& a : spec.grid)
		for (const auto& v : a.values)
			checkWithLoader(derive(base, {a}, {{a.name, v}}),
			                spec.file + ": [grid] " + a.name + " = " + v +
			                    ": on " + config.written);
	return base;
}

/** Combination \a c of the grid's values (the last key varies fastest). */
Overrides gridCombination(const std::vector<GridAxis>& grid, size_t c)
{
	Overrides ov;
	for (size_t i = 0, rest = c; i < grid.size(); i++)
	{
		size_t stride = 1;
		for (size_t j = i + 1; j < grid.size(); j++)
			stride *= grid[j].values.size();
		ov.emplace_back(grid[i].name, grid[i].values[rest / stride]);
		rest %= stride;
	}
	return ov;
}

/** A run's id: its number (\a digits wide), then what tells it apart:
 * the config, the grid values, the rawlog (each when there are several). */
std::string runId(const SweepSpec& spec, size_t number, size_t digits,
                  const ListedFile& config, const Overrides& ov,
                  const std::vector<std::string>& shortKeys,
                  const ListedFile& rawlog)
{
	const std::string num = std::to_string(number);
	std::string id = std::string(digits - num.size(), '0') + num;
	if (spec.configs.size() > 1) id += "_" + idPart(stem(config.path));
	for (size_t i = 0; i < ov.size(); i++)
		id += "_" + idPart(shortKeys[i]) + "=" + idPart(ov[i].second);
	if (spec.rawlogs.size() > 1) id += "_" + idPart(stem(rawlog.path));
	return id;
}
}  // namespace

SweepPlan SweepPlan::make(const SweepSpec& spec)
{
	SweepPlan plan;
	plan.name = spec.name;
	plan.sweepFile = spec.file;
	plan.frames = spec.frames;
	plan.truth = spec.truth;
	for (const auto& a : spec.grid) plan.gridKeys.push_back(a.name);
	for (const auto& a : spec.constants)
		plan.constants.emplace_back(a.name, a.values[0]);

	size_t combos = 1;
	for (const auto& a : spec.grid) combos *= a.values.size();
	const auto shortKeys = shortGridKeys(plan.gridKeys);
	const size_t n = spec.configs.size() * combos * spec.rawlogs.size();
	const size_t digits = std::to_string(n).size();

	for (const auto& config : spec.configs)
	{
		const std::string base = checkedBase(spec, plan, config);
		for (size_t c = 0; c < combos; c++)
		{
			const Overrides ov = gridCombination(spec.grid, c);
			const std::string text = derive(base, spec.grid, ov);
			if (ov.size() > 1)  // the combination (each value alone passed)
			{
				std::string combo;
				for (const auto& [k, v] : ov)
					combo += (combo.empty() ? "" : ", ") + k + " = " + v;
				checkWithLoader(text, spec.file + ": [grid] " + combo +
				                          ": on " + config.written);
			}
			for (size_t k = 0; k < spec.rawlogs.size(); k++)
			{
				RunSpec r;
				r.config = config;
				r.rawlog = spec.rawlogs[k];
				r.truthMasks = spec.truth.masks[k];
				r.truthTrajectory = spec.truth.trajectories[k];
				r.overrides = ov;
				r.configText = text;
				r.id = runId(spec, plan.runs.size() + 1, digits, config, ov,
				             shortKeys, r.rawlog);
				plan.runs.push_back(std::move(r));
			}
		}
	}
	return plan;
}

Json SweepPlan::toJson() const
{
	Json j;
	j["name"] = name;
	j["sweep_file"] = sweepFile;
	j["frames"] = frames;
	j["grid"] = gridKeys;
	Json& cs = j["constants"] = Json::object();
	for (const auto& [k, v] : constants) cs[k] = v;
	if (truth.any())
		j["truth"] = {{"moving_value", truth.movingValue},
		              {"static_value", truth.staticValue},
		              {"ignore_values", truth.ignoreValues},
		              {"depth_valid", truth.depthValid}};
	Json& rs = j["runs"] = Json::array();
	for (const auto& r : runs)
	{
		Json o;
		for (const auto& [k, v] : r.overrides) o[k] = v;
		Json run = {{"id", r.id},
		            {"config", r.config.written},
		            {"config_path", r.config.path},
		            {"rawlog", r.rawlog.written},
		            {"rawlog_path", r.rawlog.path},
		            {"overrides", o}};
		if (!r.truthMasks.empty()) run["truth_masks"] = r.truthMasks;
		if (!r.truthTrajectory.empty())
			run["truth_trajectory"] = r.truthTrajectory;
		rs.push_back(std::move(run));
	}
	return j;
}

SweepPlan SweepPlan::readJson(const std::string& path)
{
	std::ifstream f(path);
	if (!f)
		throw std::runtime_error(path + ": cannot open (" +
		                         std::strerror(errno) +
		                         "): not the output folder of bims-sweep?");
	try
	{
		const Json j = Json::parse(f);
		SweepPlan p;
		p.name = j.at("name").get<std::string>();
		p.sweepFile = j.at("sweep_file").get<std::string>();
		p.frames = j.at("frames").get<std::string>();
		p.gridKeys = j.at("grid").get<std::vector<std::string>>();
		// (plans of earlier versions have no constants nor truth)
		const Json constants = j.value("constants", Json::object());
		for (const auto& [k, v] : constants.items())
			p.constants.emplace_back(k, v.get<std::string>());
		if (j.contains("truth"))
		{
			const Json& t = j.at("truth");
			p.truth.movingValue = t.at("moving_value").get<int>();
			p.truth.staticValue = t.at("static_value").get<int>();
			p.truth.ignoreValues = t.at("ignore_values").get<std::string>();
			p.truth.depthValid = t.at("depth_valid").get<bool>();
		}
		for (const auto& o : j.at("runs"))
		{
			RunSpec r;
			r.id = o.at("id").get<std::string>();
			if (r.id.empty() || r.id.find('/') != std::string::npos ||
			    r.id == "." || r.id == "..")
				throw std::runtime_error("bad run id '" + r.id + "'");
			r.config = {o.at("config").get<std::string>(),
			            o.at("config_path").get<std::string>()};
			r.rawlog = {o.at("rawlog").get<std::string>(),
			            o.at("rawlog_path").get<std::string>()};
			for (const auto& k : p.gridKeys)
				r.overrides.emplace_back(
				    k, o.at("overrides").at(k).get<std::string>());
			r.truthMasks = o.value("truth_masks", std::string());
			r.truthTrajectory = o.value("truth_trajectory", std::string());
			p.truth.masks.push_back(r.truthMasks);
			p.truth.trajectories.push_back(r.truthTrajectory);
			p.runs.push_back(std::move(r));
		}
		return p;
	}
	catch (const std::exception& e)
	{
		throw std::runtime_error(path + ": not a bims-sweep plan: " + e.what());
	}
}

std::string constantsText(const SweepPlan& plan)
{
	std::string out;
	for (const auto& [k, v] : plan.constants)
		out += (out.empty() ? "" : ", ") + k + "=" + v;
	return out;
}

std::vector<std::string> shortGridKeys(const std::vector<std::string>& keys)
{
	const auto keyOf = [](const std::string& name)
	{ return name.substr(name.find('.') + 1); };
	std::vector<std::string> out;
	for (const auto& a : keys)
	{
		size_t same = 0;
		for (const auto& b : keys) same += keyOf(b) == keyOf(a);
		out.push_back(same > 1 ? a : keyOf(a));
	}
	return out;
}

std::string runDir(const std::string& outDir, const std::string& id)
{
	return (fs::path(outDir) / "runs" / id).string();
}

std::string runOutDir(const std::string& outDir, const std::string& id)
{
	return runDir(outDir, id) + "/out";
}

std::vector<std::string> runCommand(const std::string& program,
                                    const SweepPlan& plan, const RunSpec& run,
                                    const std::string& outDir)
{
	const std::string dir =
	    fs::absolute(runDir(outDir, run.id)).lexically_normal().string();
	std::vector<std::string> argv = {program, dir + "/config.ini",
	                                 run.rawlog.path};
	if (!plan.frames.empty())
	{
		argv.push_back("--frames");
		argv.push_back(plan.frames);
	}
	// the run's folder is the sweep's: a run done again replaces it
	argv.insert(argv.end(), {"-o", dir + "/out", "--overwrite", "-q"});
	return argv;
}

void writePlan(const SweepPlan& plan, const std::string& outDir)
{
	makeDirs(outDir);
	writeJsonFile(outDir + "/sweep.json", plan.toJson());
	for (const auto& r : plan.runs)
	{
		const std::string dir = runDir(outDir, r.id);
		makeDirs(dir);
		writeFileAtomically(dir + "/config.ini", r.configText);
		const std::string old = runOutDir(outDir, r.id) + "/metrics.json";
		if (std::remove(old.c_str()) != 0 && errno != ENOENT)
			throw std::runtime_error(
			    old + ": cannot remove: " + std::strerror(errno));
	}
}

std::string shellLine(const std::vector<std::string>& argv)
{
	std::string line;
	for (const auto& a : argv)
	{
		bool plain = !a.empty();
		for (char c : a)
			plain &= std::isalnum(static_cast<unsigned char>(c)) ||
			         std::strchr("/._=+:,@%-", c) != nullptr;
		std::string w = "'";
		for (char c : a)
			w += c == '\'' ? std::string("'\\''") : std::string(1, c);
		line += (line.empty() ? "" : " ") + (plain ? a : w + "'");
	}
	return line;
}

void writeJobsFile(const std::string& path, const std::string& program,
                   const SweepPlan& plan, const std::string& outDir)
{
	std::string text;
	for (const auto& r : plan.runs)
		text += shellLine(runCommand(program, plan, r, outDir)) + " > " +
		        shellLine({fs::absolute(runDir(outDir, r.id) + "/log.txt")
		                       .lexically_normal()
		                       .string()}) +
		        " 2>&1\n";
	writeFileAtomically(path, text);
}

}  // namespace bims::sweep
