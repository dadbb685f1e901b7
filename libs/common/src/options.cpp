#include <bims/common/options.h>

#include <algorithm>
#include <charconv>
#include <stdexcept>

namespace bims
{
std::string choiceList(const std::vector<std::string>& names)
{
	std::string list;
	for (const auto& n : names) list += (list.empty() ? "" : "|") + n;
	return list;
}

std::string badChoiceMessage(const std::string& value,
                             const std::vector<std::string>& names)
{
	return "'" + value + "' is not one of " + choiceList(names);
}

std::string formatReal(double v)
{
	char buf[64];
	const auto r = std::to_chars(buf, buf + sizeof buf, v);
	return std::string(buf, r.ptr);
}

namespace
{
std::string joinReals(const double* v, std::size_t n)
{
	std::string s;
	for (std::size_t i = 0; i < n; i++) s += (i ? " " : "") + formatReal(v[i]);
	return s;
}
std::string interval(double min, double max)
{
	return "[" + formatReal(min) + ", " + formatReal(max) + "]";
}
const char* boolName(bool v)
{
	return v ? "true" : "false";
}
}  // namespace

// --- OptionReader ----------------------------------------------------------

void OptionReader::onReal(const char* key, double& v, double min, double max,
                          const char*)
{
	v = s_.getDouble(key, v, min, max);
}
void OptionReader::onInteger(const char* key, long& v, long min, long max,
                             const char*)
{
	v = s_.getInt(key, v, min, max);
}
void OptionReader::onFlag(const char* key, bool& v, const char*)
{
	v = s_.getBool(key, v);
}
void OptionReader::onText(const char* key, std::string& v, const char*)
{
	v = s_.getString(key, v);
}
void OptionReader::onReals(const char* key, double* v, std::size_t n,
                           double min, double max, const char*)
{
	const auto r =
	    s_.getDoubles(key, std::vector<double>(v, v + n), n, min, max);
	std::copy(r.begin(), r.end(), v);
}
void OptionReader::onChoice(const char* key, std::string& name,
                            const std::vector<std::string>& names, const char*)
{
	name = s_.getChoice(key, name, names);
}
void OptionReader::onBrokenRule(const char* key, const std::string& what)
{
	s_.fail(key, what);
}
bool OptionReader::onGroup(const std::vector<const char*>& keys, bool)
{
	std::size_t n = 0;
	for (const char* k : keys) n += s_.has(k) ? 1 : 0;
	if (n > 0 && n < keys.size())
	{
		std::string all, given, missing;
		for (const char* k : keys)
		{
			all += (all.empty() ? "" : " ") + std::string(k);
			(s_.has(k) ? given : missing) += std::string(" ") + k;
		}
		for (const char* k : keys)
			if (!s_.has(k))
				s_.fail(k, all + ": all or none; given:" + given +
				               ", missing:" + missing);
	}
	return n == keys.size();
}
void OptionReader::onOther(const char* key)
{
	s_.allow(key);
}

// --- OptionChecker ---------------------------------------------------------

void OptionChecker::fail(const char* key, const std::string& what) const
{
	throw std::invalid_argument(who_ + ": " + key + " " + what);
}
void OptionChecker::onReal(const char* key, double& v, double min, double max,
                           const char*)
{
	if (!(v >= min && v <= max))  // NaN fails too
		fail(key, "= " + formatReal(v) + ": must be in " + interval(min, max));
}
void OptionChecker::onInteger(const char* key, long& v, long min, long max,
                              const char*)
{
	if (v < min || v > max)
		fail(key, "= " + std::to_string(v) + ": must be in [" +
		              std::to_string(min) + ", " + std::to_string(max) + "]");
}
void OptionChecker::onReals(const char* key, double* v, std::size_t n,
                            double min, double max, const char* doc)
{
	for (std::size_t i = 0; i < n; i++) onReal(key, v[i], min, max, doc);
}
void OptionChecker::onChoice(const char* key, std::string& name,
                             const std::vector<std::string>& names, const char*)
{
	if (std::find(names.begin(), names.end(), name) == names.end())
		fail(key, "= " + name + ": must be one of " + choiceList(names));
}
void OptionChecker::onBrokenRule(const char* key, const std::string& what)
{
	fail(key, what);
}

// --- OptionWriter ----------------------------------------------------------

void OptionWriter::put(const char* key, const std::string& value,
                       const char* doc)
{
	// MRPT would read the comment of an empty value as the value
	out_.write(section_, key, value, -1, -1, value.empty() ? "" : doc);
}
void OptionWriter::onReal(const char* key, double& v, double, double,
                          const char* doc)
{
	put(key, formatReal(v), doc);
}
void OptionWriter::onInteger(const char* key, long& v, long, long,
                             const char* doc)
{
	put(key, std::to_string(v), doc);
}
void OptionWriter::onFlag(const char* key, bool& v, const char* doc)
{
	put(key, boolName(v), doc);
}
void OptionWriter::onText(const char* key, std::string& v, const char* doc)
{
	put(key, v, doc);
}
void OptionWriter::onReals(const char* key, double* v, std::size_t n, double,
                           double, const char* doc)
{
	put(key, joinReals(v, n), doc);
}
void OptionWriter::onChoice(const char* key, std::string& name,
                            const std::vector<std::string>&, const char* doc)
{
	put(key, name, doc);
}

// --- OptionTable -----------------------------------------------------------

void OptionTable::add(const char* key, std::string value, std::string range,
                      const char* doc)
{
	if (std::find(absent_.begin(), absent_.end(), key) != absent_.end())
		value = "(none)";
	rows.push_back({key, std::move(value), std::move(range), doc});
}
void OptionTable::onReal(const char* key, double& v, double min, double max,
                         const char* doc)
{
	add(key, formatReal(v), interval(min, max), doc);
}
void OptionTable::onInteger(const char* key, long& v, long min, long max,
                            const char* doc)
{
	add(key, std::to_string(v),
	    "[" + std::to_string(min) + ", " + std::to_string(max) + "]", doc);
}
void OptionTable::onFlag(const char* key, bool& v, const char* doc)
{
	add(key, boolName(v), "true|false", doc);
}
void OptionTable::onText(const char* key, std::string& v, const char* doc)
{
	add(key, v, "text", doc);
}
void OptionTable::onReals(const char* key, double* v, std::size_t n, double min,
                          double max, const char* doc)
{
	add(key, joinReals(v, n),
	    std::to_string(n) + " reals in " + interval(min, max), doc);
}
void OptionTable::onChoice(const char* key, std::string& name,
                           const std::vector<std::string>& names,
                           const char* doc)
{
	add(key, name, choiceList(names), doc);
}
bool OptionTable::onGroup(const std::vector<const char*>& keys, bool given)
{
	if (!given) absent_.insert(absent_.end(), keys.begin(), keys.end());
	return true;
}

}  // namespace bims
