// Runs a fuzz target's LLVMFuzzerTestOneInput() over files and folders of
// inputs, without libFuzzer: CTest's regression run over the committed
// corpus (a crash or a sanitizer report fails it; a target's expected
// errors are caught inside the target).
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

#include "fuzz_common.h"

namespace fs = std::filesystem;

int main(int argc, char** argv)
{
	if (argc < 2)
	{
		std::cerr << "usage: " << argv[0] << " INPUT|FOLDER...\n";
		return 2;
	}
	size_t n = 0;
	for (int i = 1; i < argc; i++)
	{
		std::vector<fs::path> files;
		if (fs::is_directory(argv[i]))
		{
			for (const auto& e : fs::directory_iterator(argv[i]))
				if (e.is_regular_file()) files.push_back(e.path());
		}
		else if (fs::is_regular_file(argv[i]))
			files.push_back(argv[i]);
		else
		{
			std::cerr << argv[i] << ": no such input file or folder\n";
			return 2;
		}
		std::sort(files.begin(), files.end());
		for (const auto& f : files)
		{
			std::ifstream in(f, std::ios::binary);
			const std::vector<char> bytes{std::istreambuf_iterator<char>(in),
			                              std::istreambuf_iterator<char>()};
			LLVMFuzzerTestOneInput(
			    reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
			++n;
		}
	}
	if (n == 0)
	{
		std::cerr << "no inputs\n";
		return 2;
	}
	std::cout << n << " inputs, no crash\n";
	return 0;
}
