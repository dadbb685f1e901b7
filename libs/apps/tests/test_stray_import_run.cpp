// bims-import-stray's report (stray_import_run.h): what it says of a
// capture without confidence maps, without IMU and with a reference.
#include <bims/apps/stray_import_run.h>
#include <gtest/gtest.h>

#include <string>

TEST(StrayImportRun, TheReportSaysWhatTheCaptureLacked)
{
	bims::eval::StrayImportSummary sum;
	sum.frames = 6;
	sum.width = 32;
	sum.height = 24;
	sum.confidence = false;
	const std::string report = bims::apps::strayImportReport("x.rawlog", sum);
	EXPECT_EQ(report.rfind("x.rawlog: 6 RGB-D frames of 32x24", 0), 0u)
	    << report;
	EXPECT_NE(report.find("no confidence/ folder: all"), std::string::npos)
	    << report;
}
