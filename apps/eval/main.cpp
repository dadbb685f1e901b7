// bims-eval traj GT.txt EST.txt [options]
// bims-eval masks GT_MASK_DIR PRED_MASK_DIR [--depth-valid IN.rawlog] [options]
// bims-eval depth-consistency IN.rawlog GT.txt [options]
// See docs/eval.md for the definitions.
#include <bims/common/app.h>

#include <cstdio>
#include <string>

#include "commands.h"

int main(int argc, char** argv)
{
	return bims::runApp(
	    "bims-eval",
	    [&]()
	    {
		    const std::string usage =
		        "usage: bims-eval traj GT.txt EST.txt [--help]\n"
		        "       bims-eval masks GT_MASK_DIR PRED_MASK_DIR "
		        "[--depth-valid "
		        "IN.rawlog] [--help]\n"
		        "       bims-eval depth-consistency IN.rawlog GT.txt [--help]";
		    if (argc < 2)
			    throw bims::UsageError("missing sub-command\n" + usage);
		    const std::string sub = argv[1];
		    if (sub == "-h" || sub == "--help")
		    {
			    std::printf("%s\n", usage.c_str());
			    return 0;
		    }
		    if (sub == "--version")
		    {
			    std::printf("bims-eval version: %s\n", bims::version());
			    return 0;
		    }
		    // The sub-command sees "bims-eval <sub>" as its program name.
		    std::string prog = std::string("bims-eval ") + sub;
		    argv[1] = prog.data();
		    if (sub == "traj") return cmdTraj(argc - 1, argv + 1);
		    if (sub == "masks") return cmdMasks(argc - 1, argv + 1);
		    if (sub == "depth-consistency")
			    return cmdDepthConsistency(argc - 1, argv + 1);
		    throw bims::UsageError("unknown sub-command '" + sub + "'\n" +
		                           usage);
	    });
}
