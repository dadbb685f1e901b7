// Options structs described once.
//
// Every parameter struct of an experiment section has
//
//   void describe(OptionVisitor& v);
//
// which names its keys in order, each with its field, its range or choices
// and a one-line meaning. That one description is walked to read a section
// (OptionReader: strict, errors name file, section and key), to write the
// values in use (OptionWriter: effective.ini, with the meaning as a comment)
// and to build the reference table of docs/config.md (OptionTable).
#pragma once

#include <bims/common/choice.h>
#include <bims/common/config.h>

#include <mrpt/config/CConfigFileBase.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace bims
{
/** What describe() calls, once per key. The public calls are the same for
 * every visitor; the visitors override the protected on*() hooks. */
class OptionVisitor
{
 public:
	virtual ~OptionVisitor() = default;

	/** A real number in [min, max]. */
	void real(const char* key, double& v, double min, double max,
	          const char* doc)
	{
		onReal(key, v, min, max, doc);
	}
	/** An integer in [min, max]. */
	template <typename Int>
	void integer(const char* key, Int& v, long min, long max, const char* doc)
	{
		long x = static_cast<long>(v);
		onInteger(key, x, min, max, doc);
		v = static_cast<Int>(x);
	}
	/** true/false. */
	void flag(const char* key, bool& v, const char* doc)
	{
		onFlag(key, v, doc);
	}
	/** Free text (e.g. a sensor label; may be empty). */
	void text(const char* key, std::string& v, const char* doc)
	{
		onText(key, v, doc);
	}
	/** \a n reals separated by spaces, each in [min, max]. */
	void reals(const char* key, double* v, std::size_t n, double min,
	           double max, const char* doc)
	{
		onReals(key, v, n, min, max, doc);
	}
	/** One of the names of enum E (its table: bims/common/choice.h). */
	template <typename E>
	void choice(const char* key, E& v, const char* doc)
	{
		const auto c = choices(v);
		std::string name = c.name(v);
		onChoice(key, name, c.names(), doc);
		v = *c.find(name);
	}
	/** A rule across keys (e.g. max above min): when reading, a value
	 * breaking it is an error naming \a key and \a what. Returns \a ok. */
	bool rule(bool ok, const char* key, const std::string& what)
	{
		if (!ok) onBrokenRule(key, what);
		return ok;
	}
	/** Keys given all together or not at all (e.g. the intrinsics): when
	 * reading, whether the file gives them (some but not all is an error);
	 * otherwise \a given. The keys are then described only if true. */
	bool group(const std::vector<const char*>& keys, bool given)
	{
		return onGroup(keys, given);
	}
	/** A key of the section read by another program (e.g. bims-import-tum):
	 * accepted when reading, not described. */
	void other(const char* key) { onOther(key); }

 protected:
	virtual void onReal(const char* key, double& v, double min, double max,
	                    const char* doc) = 0;
	virtual void onInteger(const char* key, long& v, long min, long max,
	                       const char* doc) = 0;
	virtual void onFlag(const char* key, bool& v, const char* doc) = 0;
	virtual void onText(const char* key, std::string& v, const char* doc) = 0;
	virtual void onReals(const char* key, double* v, std::size_t n, double min,
	                     double max, const char* doc) = 0;
	virtual void onChoice(const char* key, std::string& name,
	                      const std::vector<std::string>& names,
	                      const char* doc) = 0;
	virtual void onBrokenRule(const char*, const std::string&) {}
	virtual bool onGroup(const std::vector<const char*>&, bool given)
	{
		return given;
	}
	virtual void onOther(const char*) {}
};

/** Reads the keys from one section through ConfigSection (absent keys keep
 * their value; out-of-range values, bad names and broken rules throw
 * ConfigError naming file, section and key). */
class OptionReader : public OptionVisitor
{
 public:
	explicit OptionReader(ConfigSection& s) : s_(s) {}

 protected:
	void onReal(const char* key, double& v, double min, double max,
	            const char*) override;
	void onInteger(const char* key, long& v, long min, long max,
	               const char*) override;
	void onFlag(const char* key, bool& v, const char*) override;
	void onText(const char* key, std::string& v, const char*) override;
	void onReals(const char* key, double* v, std::size_t n, double min,
	             double max, const char*) override;
	void onChoice(const char* key, std::string& name,
	              const std::vector<std::string>& names, const char*) override;
	void onBrokenRule(const char* key, const std::string& what) override;
	bool onGroup(const std::vector<const char*>& keys, bool given) override;
	void onOther(const char* key) override;

 private:
	ConfigSection& s_;
};

/** Reads \a opts (anything with describe()) from \a section of \a cfg:
 * every key described, nothing else (ConfigSection::finish). */
template <typename Options>
void readOptions(Options& opts, const mrpt::config::CConfigFileBase& cfg,
                 const std::string& section)
{
	ConfigSection s(cfg, section);
	OptionReader r(s);
	opts.describe(r);
	s.finish();
}

/** Checks values set in code (not read from a file) against their declared
 * ranges, choices and rules: the first that breaks one throws
 * std::invalid_argument "WHO: KEY = VALUE: must be in [MIN, MAX]" (or
 * "must be one of a|b", or the rule's text). A params struct's validate()
 * is checkOptions(*this, "...") and nothing else: its ranges are those of
 * its describe(), one place. */
class OptionChecker : public OptionVisitor
{
 public:
	explicit OptionChecker(std::string who) : who_(std::move(who)) {}

 protected:
	void onReal(const char* key, double& v, double min, double max,
	            const char*) override;
	void onInteger(const char* key, long& v, long min, long max,
	               const char*) override;
	void onFlag(const char*, bool&, const char*) override {}
	void onText(const char*, std::string&, const char*) override {}
	void onReals(const char* key, double* v, std::size_t n, double min,
	             double max, const char*) override;
	void onChoice(const char* key, std::string& name,
	              const std::vector<std::string>& names, const char*) override;
	void onBrokenRule(const char* key, const std::string& what) override;

 private:
	[[noreturn]] void fail(const char* key, const std::string& what) const;
	std::string who_;
};

/** Throws std::invalid_argument naming \a who and the first key of
 * \a opts out of its declared range (OptionChecker). */
template <typename Options>
void checkOptions(Options opts, const std::string& who)
{
	OptionChecker c(who);
	opts.describe(c);
}

/** Writes every key with its value into \a section of \a out (MRPT's
 * CConfigFileBase::write, the meaning as a "// " comment, which MRPT
 * strips when it reads the value back; none after an empty value, which
 * MRPT would read as the comment). Reals are written with the fewest
 * characters that read back to the same double (formatReal). */
class OptionWriter : public OptionVisitor
{
 public:
	OptionWriter(mrpt::config::CConfigFileBase& out, std::string section)
	    : out_(out), section_(std::move(section))
	{
	}

 protected:
	void onReal(const char* key, double& v, double, double,
	            const char* doc) override;
	void onInteger(const char* key, long& v, long, long,
	               const char* doc) override;
	void onFlag(const char* key, bool& v, const char* doc) override;
	void onText(const char* key, std::string& v, const char* doc) override;
	void onReals(const char* key, double* v, std::size_t n, double, double,
	             const char* doc) override;
	void onChoice(const char* key, std::string& name,
	              const std::vector<std::string>&, const char* doc) override;

 private:
	void put(const char* key, const std::string& value, const char* doc);
	mrpt::config::CConfigFileBase& out_;
	std::string section_;
};

/** Writes a copy of \a opts into \a section of \a out (OptionWriter). */
template <typename Options>
void writeOptions(Options opts, mrpt::config::CConfigFileBase& out,
                  const std::string& section)
{
	OptionWriter w(out, section);
	opts.describe(w);
}

/** One row of the reference table: a key, its value, its range or
 * choices ("[0, 1]", "a|b", "true|false", "text") and its meaning. */
struct OptionRow
{
	std::string key, value, range, doc;
};

/** Collects the rows of one section (every key, groups included). */
class OptionTable : public OptionVisitor
{
 public:
	std::vector<OptionRow> rows;

 protected:
	void onReal(const char* key, double& v, double min, double max,
	            const char* doc) override;
	void onInteger(const char* key, long& v, long min, long max,
	               const char* doc) override;
	void onFlag(const char* key, bool& v, const char* doc) override;
	void onText(const char* key, std::string& v, const char* doc) override;
	void onReals(const char* key, double* v, std::size_t n, double min,
	             double max, const char* doc) override;
	void onChoice(const char* key, std::string& name,
	              const std::vector<std::string>& names,
	              const char* doc) override;
	/** Describes the keys of a group also when not given (their value
	 * then reads "(none)"). */
	bool onGroup(const std::vector<const char*>& keys, bool given) override;

 private:
	void add(const char* key, std::string value, std::string range,
	         const char* doc);
	std::vector<std::string> absent_;
};

/** The rows of a copy of \a opts (OptionTable). */
template <typename Options>
std::vector<OptionRow> optionRows(Options opts)
{
	OptionTable t;
	opts.describe(t);
	return t.rows;
}

/** A real in the fewest characters that read back to it (std::to_chars):
 * 0.05, 10, 1e-09. */
std::string formatReal(double v);

}  // namespace bims
