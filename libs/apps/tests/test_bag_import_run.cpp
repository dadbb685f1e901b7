// bims-import-bag's report (bag_import_run.h): what it says of an import
// whose camera had a distortion bims does not model, and of stamps that went
// back.
#include <bims/apps/bag_import_run.h>
#include <gtest/gtest.h>

#include <string>

TEST(BagImportRun, TheReportNamesAnIgnoredDistortion)
{
	bims::bag::BagImportSummary sum;
	sum.frames = 4;
	sum.stampsBack = 1;
	sum.distortionIgnored = true;
	sum.distortionModel = "plumb_bob";
	const std::string r = bims::apps::bagImportReport("o", sum, {});
	EXPECT_NE(r.find("plumb_bob distortion is not modelled"), std::string::npos)
	    << r;
	sum.distortionIgnored = false;
	EXPECT_EQ(bims::apps::bagImportReport("o", sum, {}).find("distortion"),
	          std::string::npos);
}
