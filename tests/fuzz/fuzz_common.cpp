#include "fuzz_common.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include <unistd.h>

namespace bims::fuzz
{
namespace
{
/** A folder of its own for the files one run writes, removed at exit (a
 *  replay test or a fuzzing run leaves nothing behind in TMPDIR). */
struct ScratchDir
{
	std::string path;
	ScratchDir()
	{
		const char* tmp = std::getenv("TMPDIR");
		path = std::string(tmp && *tmp ? tmp : "/tmp") + "/bims-fuzz-XXXXXX";
		if (!mkdtemp(path.data()))
			throw std::runtime_error("fuzz: cannot make a scratch folder");
	}
	~ScratchDir()
	{
		std::error_code ec;
		std::filesystem::remove_all(path, ec);
	}
	ScratchDir(const ScratchDir&) = delete;
	ScratchDir& operator=(const ScratchDir&) = delete;
};
}  // namespace

const std::string& scratchDir()
{
	static const ScratchDir dir;
	return dir.path;
}

std::string writeFile(const std::string& name, const uint8_t* data, size_t size)
{
	const std::string path = scratchDir() + "/" + name;
	FILE* f = std::fopen(path.c_str(), "wb");
	if (!f) throw std::runtime_error("fuzz: cannot write " + path);
	// (an empty input may come as a null pointer: not given to fwrite)
	const bool ok = size == 0 || std::fwrite(data, 1, size, f) == size;
	if (std::fclose(f) != 0 || !ok)
		throw std::runtime_error("fuzz: cannot write " + path);
	return path;
}

std::vector<std::string> splitParts(const uint8_t* data, size_t size, size_t n)
{
	const std::string s(reinterpret_cast<const char*>(data), size);
	const std::string sep = "\n--\n";
	std::vector<std::string> parts;
	size_t pos = 0;
	while (parts.size() + 1 < n)
	{
		const size_t at = s.find(sep, pos);
		if (at == std::string::npos) break;
		parts.push_back(s.substr(pos, at - pos));
		pos = at + sep.size();
	}
	parts.push_back(s.substr(pos));
	parts.resize(n);
	return parts;
}
}  // namespace bims::fuzz
