// bims-eval traj GT.txt EST.txt [options]
// bims-eval masks GT_MASK_DIR PRED_MASK_DIR [--depth-valid IN.rawlog] [options]
// bims-eval depth-consistency IN.rawlog GT.txt [options]
// bims-eval attitude REF.txt EST.txt [--ref-up AXIS] [options]
// See docs/eval.md for the definitions.
#include <bims/apps/app.h>

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
		        "       bims-eval depth-consistency IN.rawlog GT.txt [--help]\n"
		        "       bims-eval attitude REF.txt EST.txt [--ref-up AXIS] "
		        "[--help]";
		    if (argc < 2)
			    throw bims::UsageError("missing sub-command\n" + usage);
		    const std::string sub = argv[1];
		    if (sub == "-h" || sub == "--help")
		    {
			    // and each sub-command's options (one page: man bims-eval)
			    std::printf("%s\n", usage.c_str());
			    for (const auto& [name, fn] :
			         {std::pair{"traj", &cmdTraj},
			          std::pair{"masks", &cmdMasks},
			          std::pair{"depth-consistency", &cmdDepthConsistency},
			          std::pair{"attitude", &cmdAttitude}})
			    {
				    std::string prog = std::string("bims-eval ") + name;
				    char help[] = "--help";
				    char* args[] = {prog.data(), help, nullptr};
				    std::printf("\n");
				    std::fflush(stdout);
				    try
				    {
					    fn(2, args);
				    }
				    catch (const bims::ExitRequest&)
				    {
				    }
			    }
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
		    if (sub == "attitude") return cmdAttitude(argc - 1, argv + 1);
		    throw bims::UsageError("unknown sub-command '" + sub + "'\n" +
		                           usage);
	    });
}
