// The whole pipeline in a program of its own: an experiment .ini (e.g. the
// installed PREFIX/share/bims/default.ini) read strictly, a Pipeline made.
//   pipeline_from_ini EXPERIMENT.ini
#include <bims/pipeline/pipeline.h>

#include <cstdio>
#include <exception>

int main(int argc, char** argv)
{
	if (argc != 2)
	{
		std::fprintf(stderr, "usage: %s EXPERIMENT.ini\n", argv[0]);
		return 2;
	}
	try
	{
		bims::pipeline::ExperimentConfig cfg;
		cfg.loadFromFile(argv[1]);
		bims::pipeline::Pipeline pipeline(cfg);
		std::printf("pipeline from %s: voxel size %g m\n", cfg.source.c_str(),
		            cfg.grids.voxel_size);
		return 0;
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "error: %s\n", e.what());
		return 1;
	}
}
