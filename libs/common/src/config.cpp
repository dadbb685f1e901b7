#include <bims/common/config.h>
#include <bims/common/errors.h>
#include <mrpt/config/CConfigFile.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace bims
{
namespace
{
std::string lower(std::string s)
{
	std::transform(s.begin(), s.end(), s.begin(),
	               [](unsigned char c)
	               { return static_cast<char>(std::tolower(c)); });
	return s;
}
std::string trim(const std::string& s)
{
	const auto b = s.find_first_not_of(" \t\r\n");
	if (b == std::string::npos) return {};
	const auto e = s.find_last_not_of(" \t\r\n");
	return s.substr(b, e - b + 1);
}
bool parseDouble(const std::string& s, double& out)
{
	const std::string t = trim(s);
	if (t.empty()) return false;
	char* end = nullptr;
	errno = 0;
	out = std::strtod(t.c_str(), &end);
	return errno == 0 && end && *end == '\0' && std::isfinite(out);
}
bool parseLong(const std::string& s, long& out)
{
	const std::string t = trim(s);
	if (t.empty()) return false;
	char* end = nullptr;
	errno = 0;
	out = std::strtol(t.c_str(), &end, 10);
	return errno == 0 && end && *end == '\0';
}
}  // namespace

// checkIniFile's checks on the lines of \a f (\a path in the messages)
void checkIniStream(std::istream& f, const std::string& path);

void checkIniFile(const std::string& path)
{
	std::error_code ec;
	if (!std::filesystem::is_regular_file(path, ec))
	{
		if (std::filesystem::exists(path, ec))
			throw ConfigError(
			    path + ": not a regular file (a folder?), not a config file");
		throw ConfigFileMissing(path + ": no such config file");
	}
	std::ifstream f(path);
	if (!f) throw ConfigError(path + ": cannot open config file");
	checkIniStream(f, path);
}

void checkIniText(const std::string& text, const std::string& name)
{
	std::istringstream in(text);
	checkIniStream(in, name);
}

void checkIniStream(std::istream& f, const std::string& path)
{
	std::map<std::string, int> sections;  // lower-case name -> line
	std::map<std::string, int> keys;      // of the current section
	std::string section, line;
	bool inSection = false;
	for (int n = 1; std::getline(f, line); n++)
	{
		const auto at = path + ":" + std::to_string(n) + ": ";
		if (n == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0)
			throw ConfigError(at +
			                  "the file starts with a UTF-8 byte-order mark "
			                  "(BOM): save it without one (MRPT would read "
			                  "its first line wrong)");
		if (std::any_of(line.begin(), line.end(),
		                [](char ch)
		                {
			                const auto c = static_cast<unsigned char>(ch);
			                return c < 0x20 && c != '\t' && c != '\r';
		                }))
			throw ConfigError(at +
			                  "binary bytes: not a text .ini file (another "
			                  "file, e.g. a rawlog, given in its place?)");
		const std::string t = trim(line);
		if (t.empty() || t[0] == ';' || t[0] == '#' || t.rfind("//", 0) == 0)
			continue;
		if (t[0] == '@')
		{
			// MRPT 2.5.8 reads @define; any other directive it skips
			if (t.rfind("@define", 0) != 0 ||
			    (t.size() > 7 &&
			     !std::isspace(static_cast<unsigned char>(t[7]))))
				throw ConfigError(at + "'" + t.substr(0, t.find(' ')) +
				                  "': MRPT's reader takes only @define "
				                  "(an @include would be skipped silently: "
				                  "copy the settings into this file)");
			continue;
		}
		if (t[0] == '[')
		{
			if (t.back() != ']')
				throw ConfigError(at + "section header '" + t +
				                  "' has no closing ']'");
			section = trim(t.substr(1, t.size() - 2));
			const auto [it, fresh] = sections.emplace(lower(section), n);
			if (!fresh)
				throw ConfigError(at + "section [" + section +
				                  "] given twice (first on line " +
				                  std::to_string(it->second) + ")");
			keys.clear();
			inSection = true;
			continue;
		}
		const auto eq = t.find('=');
		if (eq == std::string::npos)
			throw ConfigError(at + "'" + t +
			                  "' is neither [section] nor key = value");
		const std::string key = trim(t.substr(0, eq));
		if (key.empty()) throw ConfigError(at + "a value without a key");
		if (!inSection)
			throw ConfigError(at + "key '" + key +
			                  "' before the first [section]");
		const auto [it, fresh] = keys.emplace(lower(key), n);
		if (!fresh)
			throw ConfigError(at + "[" + section + "] " + key +
			                  " given twice (first on line " +
			                  std::to_string(it->second) + ")");
	}
}

std::unique_ptr<mrpt::config::CConfigFile> openIniFile(const std::string& path)
{
	checkIniFile(path);
	try
	{
		return std::make_unique<mrpt::config::CConfigFile>(path);
	}
	catch (const std::exception& e)
	{
		// e.g. ${UNDEFINED}: MRPT's message without its backtrace
		throw ConfigError(path + ": " + withoutBacktrace(e.what()));
	}
}

std::string configSourceName(const mrpt::config::CConfigFileBase& cfg)
{
	if (const auto* f = dynamic_cast<const mrpt::config::CConfigFile*>(&cfg))
		return f->getAssociatedFile();
	return "<memory>";
}

ConfigSection::ConfigSection(const mrpt::config::CConfigFileBase& cfg,
                             std::string section, bool required)
    : cfg_(cfg), section_(std::move(section)), file_(configSourceName(cfg))
{
	exists_ = cfg_.sectionExists(section_);
	if (required && !exists_)
		throw ConfigError(file_ + ": missing required section [" + section_ +
		                  "]");
}

bool ConfigSection::has(const std::string& key) const
{
	return exists_ && cfg_.keyExists(section_, key);
}

void ConfigSection::fail(const std::string& key, const std::string& what) const
{
	throw ConfigError(file_ + ": [" + section_ + "] " + key + ": " + what);
}

std::string ConfigSection::raw(const std::string& key) const
{
	return trim(cfg_.read_string(section_, key, "", false));
}

void ConfigSection::allow(const std::string& key)
{
	known_.insert(lower(key));
}

double ConfigSection::getDouble(const std::string& key, double def, double min,
                                double max)
{
	allow(key);
	if (!has(key)) return def;
	double v = 0;
	if (!parseDouble(raw(key), v))
		fail(key, "'" + raw(key) + "' is not a finite number");
	if (v < min || v > max)
	{
		std::ostringstream ss;
		ss << "value " << v << " out of range [" << min << ", " << max << "]";
		fail(key, ss.str());
	}
	return v;
}

double ConfigSection::requireDouble(const std::string& key, double min,
                                    double max)
{
	if (!has(key)) fail(key, "required key is missing");
	return getDouble(key, 0.0, min, max);
}

long ConfigSection::getInt(const std::string& key, long def, long min, long max)
{
	allow(key);
	if (!has(key)) return def;
	long v = 0;
	if (!parseLong(raw(key), v))
		fail(key, "'" + raw(key) + "' is not an integer");
	if (v < min || v > max)
	{
		std::ostringstream ss;
		ss << "value " << v << " out of range [" << min << ", " << max << "]";
		fail(key, ss.str());
	}
	return v;
}

long ConfigSection::requireInt(const std::string& key, long min, long max)
{
	if (!has(key)) fail(key, "required key is missing");
	return getInt(key, 0, min, max);
}

bool ConfigSection::getBool(const std::string& key, bool def)
{
	allow(key);
	if (!has(key)) return def;
	const std::string v = lower(raw(key));
	if (v == "1" || v == "true" || v == "yes" || v == "on") return true;
	if (v == "0" || v == "false" || v == "no" || v == "off") return false;
	fail(key, "'" + raw(key) + "' is not a boolean (true/false)");
}

std::string ConfigSection::getString(const std::string& key,
                                     const std::string& def)
{
	allow(key);
	if (!has(key)) return def;
	return raw(key);
}

std::string ConfigSection::requireString(const std::string& key)
{
	if (!has(key)) fail(key, "required key is missing");
	const std::string v = getString(key, "");
	if (v.empty()) fail(key, "must not be empty");
	return v;
}

std::string ConfigSection::getChoice(const std::string& key,
                                     const std::string& def,
                                     const std::vector<std::string>& names)
{
	const std::string v = getString(key, def);
	if (std::find(names.begin(), names.end(), v) == names.end())
		fail(key, badChoiceMessage(v, names));
	return v;
}

std::vector<double> ConfigSection::getDoubles(const std::string& key,
                                              const std::vector<double>& def,
                                              size_t n, double min, double max)
{
	allow(key);
	if (!has(key)) return def;
	std::string s = raw(key);
	for (char& c : s)
		if (c == ',' || c == '[' || c == ']' || c == ';') c = ' ';
	std::istringstream ss(s);
	std::vector<double> out;
	std::string tok;
	while (ss >> tok)
	{
		double v = 0;
		if (!parseDouble(tok, v))
			fail(key, "'" + tok + "' is not a finite number");
		if (v < min || v > max)
		{
			std::ostringstream m;
			m << "value " << v << " out of range [" << min << ", " << max
			  << "]";
			fail(key, m.str());
		}
		out.push_back(v);
	}
	if (out.size() != n)
		fail(key, "expected " + std::to_string(n) + " numbers, got " +
		              std::to_string(out.size()));
	return out;
}

std::vector<std::string> ConfigSection::getWords(const std::string& key)
{
	std::istringstream ss(getString(key, ""));
	std::vector<std::string> out;
	for (std::string w; ss >> w;) out.push_back(w);
	return out;
}

std::vector<std::string> ConfigSection::getList(const std::string& key)
{
	if (!has(key))
	{
		allow(key);
		return {};
	}
	const std::string v = getString(key, "");
	std::vector<std::string> out;
	for (size_t b = 0;;)
	{
		const size_t e = v.find(',', b);
		out.push_back(trim(v.substr(b, e == std::string::npos ? e : e - b)));
		if (out.back().empty())
			fail(key, "'" + v + "': an empty item in the comma-separated list");
		if (e == std::string::npos) return out;
		b = e + 1;
	}
}

void ConfigSection::finish() const
{
	if (!exists_) return;
	std::vector<std::string> keys;
	cfg_.getAllKeys(section_, keys);
	for (const auto& k : keys)
	{
		if (known_.count(lower(k))) continue;
		std::string list;
		for (const auto& a : known_) list += (list.empty() ? "" : ", ") + a;
		throw ConfigError(file_ + ": [" + section_ + "] " + k +
		                  ": unknown key (known keys: " + list + ")");
	}
}

void checkSections(const mrpt::config::CConfigFileBase& cfg,
                   const std::vector<std::string>& allowed,
                   const std::vector<std::string>& allowedPrefixes)
{
	std::vector<std::string> sections;
	cfg.getAllSections(sections);
	for (const auto& s : sections)
	{
		if (s.empty()) continue;
		const std::string ls = lower(s);
		bool ok = false;
		for (const auto& a : allowed) ok = ok || ls == lower(a);
		for (const auto& p : allowedPrefixes)
			ok = ok || ls.rfind(lower(p), 0) == 0;
		if (!ok)
		{
			std::string list;
			for (const auto& a : allowed)
				list += (list.empty() ? "" : ", ") + a;
			throw ConfigError(configSourceName(cfg) + ": [" + s +
			                  "]: unknown section (known sections: " + list +
			                  ")");
		}
	}
}

}  // namespace bims
