// JSON text that any parser reads back, whatever the strings hold.
#include <bims/io/json.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include <bims_test/tmp_dir.h>

TEST(Json, ControlCharactersQuotesAndBadBytesStayValid)
{
	const std::string nasty =
	    std::string("a\"b\\c\nd\te\x01\x1f f") + "\xff\xfe" + " g";
	bims::Json j;
	j["error"] = nasty;
	j["config"] = "conf\"ig.ini";
	const std::string text = bims::jsonText(j);
	for (const char c : text)
		EXPECT_TRUE(c == '\n' || static_cast<unsigned char>(c) >= 0x20) << text;
	const auto back = bims::Json::parse(text);  // throws if invalid
	EXPECT_EQ(back["config"], "conf\"ig.ini");
	EXPECT_EQ(back["error"].get<std::string>().substr(0, 13),
	          "a\"b\\c\nd\te\x01\x1f f");
}

TEST(Json, NumbersAreRoundedAndNonFiniteIsNull)
{
	EXPECT_EQ(bims::jsonNumber(12.34567, 3).dump(), "12.346");
	EXPECT_EQ(bims::jsonNumber(1.0 / 3).dump(), "0.333333333");
	EXPECT_EQ(bims::jsonNumber(NAN).dump(), "null");
	EXPECT_EQ(bims::jsonNumber(INFINITY, 2).dump(), "null");
}

TEST(Json, WrittenFileParses)
{
	const std::string p = bims::test::tmpPath("bims_test_io", "written.json");
	bims::Json j;
	j["k"] = "v\x02";
	bims::writeJsonFile(p, j);
	std::ifstream f(p);
	std::stringstream s;
	s << f.rdbuf();
	EXPECT_EQ(bims::Json::parse(s.str())["k"], "v\x02");
}
