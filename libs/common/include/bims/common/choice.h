// Choice options: an enum read from an .ini by name.
//
// Each such enum has one table of its .ini names, declared beside it as
//
//   inline Choices<DecayMode> choices(DecayMode)
//   {
//       static constexpr ChoiceName<DecayMode> t[] = {
//           {DecayMode::All, "all"}, {DecayMode::Frustum, "frustum"}, ...};
//       return t;
//   }
//
// (found by argument-dependent lookup). The table parses the option once,
// when the .ini is read (ConfigSection / OptionVisitor::choice), prints it
// back (choiceName: effective.ini, metrics, messages) and lists the valid
// names in errors and in docs/config.md. Code compares enum values, never
// strings.
#pragma once

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bims
{
/** One value of a choice enum and its name in .ini files. */
template <typename E>
struct ChoiceName
{
	E value;
	const char* name;
};

/** A view of an enum's table of names (static storage). */
template <typename E>
class Choices
{
 public:
	template <std::size_t N>
	constexpr Choices(const ChoiceName<E> (&table)[N])  // NOLINT: implicit
	    : table_(table), size_(N)
	{
	}

	const ChoiceName<E>* begin() const { return table_; }
	const ChoiceName<E>* end() const { return table_ + size_; }

	/** The name of \a v ("?" if the table lacks it: a bug). */
	const char* name(E v) const
	{
		for (const auto& c : *this)
			if (c.value == v) return c.name;
		return "?";
	}
	/** The value named \a s (exact, case-sensitive), if any. */
	std::optional<E> find(std::string_view s) const
	{
		for (const auto& c : *this)
			if (s == c.name) return c.value;
		return std::nullopt;
	}
	/** The names in table order. */
	std::vector<std::string> names() const
	{
		std::vector<std::string> v;
		for (const auto& c : *this) v.emplace_back(c.name);
		return v;
	}

 private:
	const ChoiceName<E>* table_;
	std::size_t size_;
};

/** "a|b|c": the valid names, for messages and docs. */
std::string choiceList(const std::vector<std::string>& names);

/** "'x' is not one of a|b|c": the error text for a bad name. */
[[nodiscard]] std::string badChoiceMessage(
    const std::string& value, const std::vector<std::string>& names);

/** The .ini name of \a v (its enum's table, found by ADL). */
template <typename E>
const char* choiceName(E v)
{
	return choices(v).name(v);
}

/** The value of enum \a E named \a s; throws std::invalid_argument
 * ("'x' is not one of a|b|c") otherwise. For command-line flags; .ini keys
 * are read with ConfigSection::getChoice, which names file, section and
 * key. */
template <typename E>
E parseChoice(const std::string& s)
{
	const auto c = choices(E{});
	if (const auto v = c.find(s)) return *v;
	throw std::invalid_argument(badChoiceMessage(s, c.names()));
}

}  // namespace bims
