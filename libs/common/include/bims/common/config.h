// Strict reading of .ini experiment files (MRPT config classes).
//
// Every key read through ConfigSection is remembered; finish() then rejects any
// key of the section that nobody read, so a typo in an .ini is an error naming
// the file, the section and the key, never a silently ignored setting.
#pragma once

#include <bims/common/choice.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileBase.h>

#include <memory>

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace bims
{
/** Error in a configuration file; the message names file, section and key. */
class ConfigError : public std::runtime_error
{
 public:
	using std::runtime_error::runtime_error;
};

/** A configuration file that does not exist (a ConfigError naming it). */
class ConfigFileMissing : public ConfigError
{
 public:
	using ConfigError::ConfigError;
};

/** Checks the syntax of the .ini file \a path before MRPT reads it (MRPT
 * keeps the last of two equal keys or sections and skips malformed lines
 * silently). Throws ConfigError naming the file and the line for: a path
 * that is not a readable regular file, a UTF-8 byte-order mark at its
 * start, a line that is neither `[section]`, `key = value`, a comment (`;`,
 * `#`, `//`) nor MRPT's `@define` (other directives, e.g. `@include`, MRPT
 * skips silently),
 * a key before the first section, a section or a key (within its section)
 * given twice; names compare without case, as MRPT looks them up. */
void checkIniFile(const std::string& path);
/** The same checks for .ini text (\a name in the messages). */
void checkIniText(const std::string& text, const std::string& name);

/** The one way bims opens an .ini: checkIniFile(path), then MRPT's reader;
 * an error of MRPT's (an undefined ${VAR}, ...) becomes a ConfigError
 * naming the file, on one line. */
std::unique_ptr<mrpt::config::CConfigFile> openIniFile(const std::string& path);

/** The file name behind a config object ("<memory>" when there is none). */
std::string configSourceName(const mrpt::config::CConfigFileBase& cfg);

/** Typed, range-checked, unknown-key-rejecting access to one .ini section. */
class ConfigSection
{
 public:
	/** \param required if true and the section is absent, throws ConfigError.
	 */
	ConfigSection(const mrpt::config::CConfigFileBase& cfg, std::string section,
	              bool required = false);

	bool exists() const { return exists_; }
	bool has(const std::string& key) const;
	const std::string& name() const { return section_; }
	const std::string& file() const { return file_; }

	/** Reads a real number in [min, max] (inclusive); default if absent. */
	double getDouble(const std::string& key, double def, double min,
	                 double max);
	/** Same, but the key must be present. */
	double requireDouble(const std::string& key, double min, double max);
	/** Reads an integer in [min, max]; default if absent. */
	long getInt(const std::string& key, long def, long min, long max);
	long requireInt(const std::string& key, long min, long max);
	/** true/false, 1/0, yes/no, on/off (any case). */
	bool getBool(const std::string& key, bool def);
	std::string getString(const std::string& key, const std::string& def);
	std::string requireString(const std::string& key);
	/** One of \a names (exact match); default if absent. Any other value
	 * is an error naming file, section, key, the value and the names. */
	std::string getChoice(const std::string& key, const std::string& def,
	                      const std::vector<std::string>& names);
	/** The same for a choice enum, by its table (bims/common/choice.h). */
	template <typename E>
	E getChoice(const std::string& key, E def)
	{
		const auto c = choices(def);
		return *c.find(getChoice(key, c.name(def), c.names()));
	}
	/** A whitespace/comma separated list of exactly \a n reals (or the
	 * default if absent), each in [min, max]. */
	std::vector<double> getDoubles(const std::string& key,
	                               const std::vector<double>& def, size_t n,
	                               double min, double max);

	/** The value's words (separated by spaces or tabs), e.g. a list of
	 * files; empty if absent. */
	std::vector<std::string> getWords(const std::string& key);
	/** The value's comma-separated items, each trimmed, e.g. "fused,
	 * flow-only"; empty if absent. An empty item (",,", a comma at either
	 * end, or an empty value) is an error naming the key. */
	std::vector<std::string> getList(const std::string& key);

	/** Marks a key as known without reading it (e.g. read by MRPT code). */
	void allow(const std::string& key);

	/** Throws ConfigError for the first key in the section that was never
	 * read nor allowed. */
	void finish() const;

	/** Throws ConfigError naming file, section and key. */
	[[noreturn]] void fail(const std::string& key,
	                       const std::string& what) const;

 private:
	std::string raw(const std::string& key) const;
	const mrpt::config::CConfigFileBase& cfg_;
	std::string section_;
	std::string file_;
	bool exists_ = false;
	std::set<std::string> known_;  // lower case
};

/** Throws ConfigError if the file has a section not in \a allowed and not
 * starting with one of \a allowedPrefixes. */
void checkSections(const mrpt::config::CConfigFileBase& cfg,
                   const std::vector<std::string>& allowed,
                   const std::vector<std::string>& allowedPrefixes = {});

}  // namespace bims
