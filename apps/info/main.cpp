// bims-info IN.rawlog: summary of any rawlog (observations per sensor label and
// class, rates, duration, time span, image sizes).
#include "summary.h"

#include <bims/apps/app.h>
#include <bims/apps/input_kind.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <iostream>

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-info",
	    [&]()
	    {
		    TCLAP::CmdLine cmd("Summary of an MRPT rawlog.", ' ',
		                       bims::version());
		    TCLAP::UnlabeledValueArg<std::string> in(
		        "rawlog", "Input rawlog", true, "", "IN.rawlog", cmd);
		    bims::parseCommandLine(cmd, argc, argv);
		    bims::apps::checkRawlogInputKind(in.getValue(),
		                                     "bims-info IN.rawlog");
		    const auto s = bims::info::summarizeRawlog(in.getValue());
		    bims::info::printSummary(s, std::cout);
		    return 0;
	    });
}
