#include <bims/common/config.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

using bims::ConfigError;
using bims::ConfigSection;

namespace
{
std::string errorOf(const std::function<void()>& f)
{
	try
	{
		f();
	}
	catch (const ConfigError& e)
	{
		return e.what();
	}
	return {};
}
}  // namespace

TEST(ConfigSection, ReadsTypedValuesAndDefaults)
{
	mrpt::config::CConfigFileMemory cfg(
	    "[a]\nx = 1.5\nn = 7\nflag = yes\nname = hello\nmode = fast\nv = 1, 2 "
	    ",3\n");
	ConfigSection s(cfg, "a");
	EXPECT_DOUBLE_EQ(s.getDouble("x", 0, 0, 10), 1.5);
	EXPECT_EQ(s.getInt("n", 0, 0, 10), 7);
	EXPECT_TRUE(s.getBool("flag", false));
	EXPECT_EQ(s.getString("name", ""), "hello");
	EXPECT_EQ(s.getEnum("mode", "slow", {"slow", "fast"}), "fast");
	EXPECT_EQ(s.getDoubles("v", {}, 3, -10, 10),
	          (std::vector<double>{1, 2, 3}));
	EXPECT_DOUBLE_EQ(s.getDouble("absent", 4.25, 0, 10), 4.25);
	EXPECT_NO_THROW(s.finish());
}

TEST(ConfigSection, UnknownKeyIsAnErrorNamingSectionAndKey)
{
	mrpt::config::CConfigFileMemory cfg("[a]\nx = 1\nxx = 2\n");
	ConfigSection s(cfg, "a");
	s.getDouble("x", 0, 0, 10);
	const auto msg = errorOf([&] { s.finish(); });
	EXPECT_NE(msg.find("[a] xx: unknown key"), std::string::npos) << msg;
	EXPECT_NE(msg.find("<memory>"), std::string::npos) << msg;
}

TEST(ConfigSection, OutOfRangeAndMalformedValuesAreErrors)
{
	mrpt::config::CConfigFileMemory cfg(
	    "[a]\nx = 11\ny = abc\nn = 2.5\nb = maybe\nm = other\nv = 1 2\n");
	ConfigSection s(cfg, "a");
	EXPECT_NE(errorOf([&] { s.getDouble("x", 0, 0, 10); }).find("out of range"),
	          std::string::npos);
	EXPECT_NE(errorOf([&] { s.getDouble("y", 0, 0, 10); }).find("[a] y:"),
	          std::string::npos);
	EXPECT_NE(errorOf([&] { s.getInt("n", 0, 0, 10); }).find("not an integer"),
	          std::string::npos);
	EXPECT_NE(errorOf([&] { s.getBool("b", false); }).find("not a boolean"),
	          std::string::npos);
	EXPECT_NE(errorOf(
	              [&] {
		              s.getEnum("m", "a", {"a", "b"});
	              })
	              .find("a|b"),
	          std::string::npos);
	EXPECT_NE(
	    errorOf([&] { s.getDoubles("v", {}, 3, 0, 9); }).find("expected 3"),
	    std::string::npos);
}

TEST(ConfigSection, RequiredKeysAndSections)
{
	mrpt::config::CConfigFileMemory cfg("[a]\nx = 1\n");
	EXPECT_NE(errorOf([&] { ConfigSection(cfg, "b", true); })
	              .find("missing required section [b]"),
	          std::string::npos);
	ConfigSection s(cfg, "a");
	EXPECT_NE(errorOf([&] { s.requireDouble("y", 0, 1); }).find("required key"),
	          std::string::npos);
	EXPECT_DOUBLE_EQ(s.requireDouble("x", 0, 1), 1.0);
}

TEST(ConfigSection, UnknownSectionsAreErrors)
{
	mrpt::config::CConfigFileMemory cfg(
	    "[a]\nx=1\n[map_voxel_00]\ny=2\n[oops]\nz=3\n");
	const auto msg =
	    errorOf([&] { bims::checkSections(cfg, {"a"}, {"map_"}); });
	EXPECT_NE(msg.find("[oops]: unknown section"), std::string::npos) << msg;
}
