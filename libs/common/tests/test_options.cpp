// Choice enums (bims/common/choice.h) and options described once
// (bims/common/options.h): read, written back, tabulated.
#include <bims/common/choice.h>
#include <bims/common/config.h>
#include <bims/common/options.h>
#include <bims_test/error_of.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <cmath>
#include <functional>
#include <limits>

using bims::test::errorOf;

namespace
{
enum class Colour
{
	Red,
	Green,
	DarkBlue
};
bims::Choices<Colour> choices(Colour)
{
	static constexpr bims::ChoiceName<Colour> t[] = {
	    {Colour::Red, "red"},
	    {Colour::Green, "green"},
	    {Colour::DarkBlue, "dark-blue"}};
	return t;
}

/** An options struct of every kind of key. */
struct Opts
{
	double gain = 0.1;
	int count = 3;
	uint32_t seed = 4294967295u;
	bool on = true;
	std::string label = "RGBD";
	double v[3] = {1.0 / 3, -2, 1e-9};
	Colour colour = Colour::Green;
	double lo = 1, hi = 2;
	bool given = false;
	double fx = 500;

	void describe(bims::OptionVisitor& o)
	{
		o.real("gain", gain, 0, 1, "a gain");
		o.integer("count", count, 1, 10, "a count");
		o.integer("seed", seed, 0, 4294967295L, "a seed");
		o.flag("on", on, "a switch");
		o.text("label", label, "a label");
		o.reals("v", v, 3, -10, 10, "three reals");
		o.choice("colour", colour, "a colour");
		o.real("lo", lo, 0, 10, "lower");
		o.real("hi", hi, 0, 10, "upper");
		o.rule(hi > lo, "hi", "must be greater than lo");
		given = o.group({"fx"}, given);
		if (given) o.real("fx", fx, 1, 1e5, "focal length");
		o.other("note");
	}
};

Opts read(const std::string& ini)
{
	mrpt::config::CConfigFileMemory cfg(ini);
	Opts o;
	bims::readOptions(o, cfg, "s");
	return o;
}

std::string written(const Opts& o)
{
	mrpt::config::CConfigFileMemory mem;
	bims::writeOptions(o, mem, "s");
	return mem.getContent();
}
}  // namespace

TEST(Choice, OneTableNamesParsesAndListsAnEnum)
{
	EXPECT_STREQ(bims::choiceName(Colour::DarkBlue), "dark-blue");
	EXPECT_EQ(bims::parseChoice<Colour>("green"), Colour::Green);
	try
	{
		bims::parseChoice<Colour>("Green");  // names compare exactly
		ADD_FAILURE() << "expected std::invalid_argument";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_STREQ(e.what(), "'Green' is not one of red|green|dark-blue");
	}
}

TEST(Choice, AnIniValueOutsideTheTableNamesFileSectionKeyValueAndChoices)
{
	mrpt::config::CConfigFileMemory cfg(
	    std::string("[paint]\ncolour = blue\nother = red\n"));
	bims::ConfigSection s(cfg, "paint");
	EXPECT_EQ(s.getChoice("other", Colour::Green), Colour::Red);
	EXPECT_EQ(s.getChoice("absent", Colour::DarkBlue), Colour::DarkBlue);
	EXPECT_EQ(
	    errorOf<bims::ConfigError>([&] { s.getChoice("colour", Colour::Red); }),
	    "<memory>: [paint] colour: 'blue' is not one of "
	    "red|green|dark-blue");
}

TEST(Options, ReadsEveryKindOfKeyAndRejectsWhatTheDescriptionForbids)
{
	const Opts o = read(
	    "[s]\ngain = 0.5\ncount = 7\nseed = 0\non = false\nlabel =\n"
	    "v = 1 2 3\ncolour = dark-blue\nfx = 400\nnote = free text\n");
	EXPECT_EQ(o.gain, 0.5);
	EXPECT_EQ(o.count, 7);
	EXPECT_EQ(o.seed, 0u);
	EXPECT_FALSE(o.on);
	EXPECT_EQ(o.label, "");
	EXPECT_EQ(o.v[2], 3);
	EXPECT_EQ(o.colour, Colour::DarkBlue);
	EXPECT_TRUE(o.given);
	EXPECT_EQ(o.fx, 400);
	// absent keys keep their values
	EXPECT_EQ(read("[s]\n").label, "RGBD");
	EXPECT_FALSE(read("[s]\n").given);

	EXPECT_EQ(errorOf<bims::ConfigError>([] { read("[s]\ngain = 2\n"); }),
	          "<memory>: [s] gain: value 2 out of range [0, 1]");
	EXPECT_EQ(errorOf<bims::ConfigError>([] { read("[s]\nlo = 3\n"); }),
	          "<memory>: [s] hi: must be greater than lo");
	EXPECT_NE(errorOf<bims::ConfigError>([] { read("[s]\ncolor = red\n"); })
	              .find("[s] color: unknown key"),
	          std::string::npos);
	EXPECT_NE(errorOf<bims::ConfigError>([] { read("[s]\ncolour = blue\n"); })
	              .find("'blue' is not one of red|green|dark-blue"),
	          std::string::npos);
}

TEST(Options, AGroupIsAllOrNothing)
{
	struct Pair
	{
		bool given = false;
		double a = 0, b = 0;
		void describe(bims::OptionVisitor& o)
		{
			given = o.group({"a", "b"}, given);
			if (!given) return;
			o.real("a", a, 0, 9, "");
			o.real("b", b, 0, 9, "");
		}
	};
	mrpt::config::CConfigFileMemory half(std::string("[s]\na = 1\n"));
	Pair p;
	EXPECT_EQ(
	    errorOf<bims::ConfigError>([&] { bims::readOptions(p, half, "s"); }),
	    "<memory>: [s] b: a b: all or none; given: a, missing: b");
}

TEST(Options, WrittenValuesReadBackToTheSameOptions)
{
	Opts o;
	o.gain = 0.1 + 0.2;  // not the shortest decimal of a "nice" number
	o.v[1] = std::nextafter(2.0, 3.0);
	o.colour = Colour::DarkBlue;
	o.label = "";
	o.given = true;
	o.fx = 525.5;
	const std::string text = written(o);
	// MRPT's writer: one "key = value // meaning" line per key
	EXPECT_NE(text.find("colour = dark-blue // a colour\n"), std::string::npos)
	    << text;
	EXPECT_NE(text.find("seed = 4294967295 // a seed\n"), std::string::npos);
	EXPECT_EQ(text.find("note"), std::string::npos);  // not described
	const Opts r = read(text);
	EXPECT_EQ(r.gain, o.gain);
	EXPECT_EQ(r.v[0], o.v[0]);
	EXPECT_EQ(r.v[1], o.v[1]);
	EXPECT_EQ(r.label, "");
	EXPECT_TRUE(r.given);
	EXPECT_EQ(written(r), text);
	// a group not given is not written, and stays not given
	EXPECT_FALSE(read(written(Opts())).given);
}

TEST(Options, RealsInTheFewestCharactersThatReadBack)
{
	EXPECT_EQ(bims::formatReal(0.05), "0.05");
	EXPECT_EQ(bims::formatReal(10), "10");
	EXPECT_EQ(bims::formatReal(1e-9), "1e-09");
	EXPECT_EQ(bims::formatReal(-2.5), "-2.5");
	for (double v : {1.0 / 3, 0.1 + 0.2, 9.80665, 1e300,
	                 std::numeric_limits<double>::denorm_min()})
		EXPECT_EQ(std::strtod(bims::formatReal(v).c_str(), nullptr), v) << v;
}

TEST(Options, TheTableListsEveryKeyWithRangeAndMeaning)
{
	const auto rows = bims::optionRows(Opts());
	ASSERT_EQ(rows.size(), 10u);  // the group's key too, "note" not
	EXPECT_EQ(rows[0].key, "gain");
	EXPECT_EQ(rows[0].value, "0.1");
	EXPECT_EQ(rows[0].range, "[0, 1]");
	EXPECT_EQ(rows[0].doc, "a gain");
	EXPECT_EQ(rows[3].range, "true|false");
	EXPECT_EQ(rows[6].value, "green");
	EXPECT_EQ(rows[6].range, "red|green|dark-blue");
	EXPECT_EQ(rows[9].key, "fx");
	EXPECT_EQ(rows[9].value, "(none)");
}

TEST(Options, TheCheckerRefusesWhatTheDescriptionForbidsNamingTheKey)
{
	auto errorOfCheck = [](const Opts& o)
	{
		try
		{
			bims::checkOptions(o, "Opts");
		}
		catch (const std::invalid_argument& e)
		{
			return std::string(e.what());
		}
		return std::string();
	};
	Opts o;
	EXPECT_EQ(errorOfCheck(o), "");
	o.gain = 1.5;
	EXPECT_EQ(errorOfCheck(o), "Opts: gain = 1.5: must be in [0, 1]");
	o.gain = std::numeric_limits<double>::quiet_NaN();
	EXPECT_EQ(errorOfCheck(o), "Opts: gain = nan: must be in [0, 1]");
	o = {};
	o.count = 0;
	EXPECT_EQ(errorOfCheck(o), "Opts: count = 0: must be in [1, 10]");
	o = {};
	o.v[2] = -11;
	EXPECT_EQ(errorOfCheck(o), "Opts: v = -11: must be in [-10, 10]");
	o = {};
	o.colour = static_cast<Colour>(7);  // not in the table
	EXPECT_EQ(errorOfCheck(o),
	          "Opts: colour = ?: must be one of red|green|dark-blue");
	o = {};
	o.lo = 3;
	EXPECT_EQ(errorOfCheck(o), "Opts: hi must be greater than lo");
	o = {};
	o.given = true;
	o.fx = 0;  // a group's keys are checked when it is given
	EXPECT_EQ(errorOfCheck(o), "Opts: fx = 0: must be in [1, 1e+05]");
}
