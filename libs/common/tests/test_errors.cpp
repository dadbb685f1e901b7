// The libraries' error texts (errors.h).
#include <bims/common/errors.h>
#include <gtest/gtest.h>

#include <string>

TEST(Errors, AnMrptExceptionIsCutToItsMessage)
{
	const std::string mrpt =
	    "==== MRPT exception ====\nLine 2: Unknown variable `${X}`\nCall "
	    "stack backtrace:\n[0 ]     0x7f5284debb28\n[1 ]     0x55cc13dc3cf4\n";
	EXPECT_EQ(bims::withoutBacktrace(mrpt), "Line 2: Unknown variable `${X}`");
	EXPECT_EQ(bims::withoutBacktrace("a.ini: plain"), "a.ini: plain");
}
