// Temporary folders for tests.
#pragma once

#include <filesystem>
#include <string>

namespace bims::test
{
/** TMP/GROUP/NAME, emptied and created. */
inline std::string freshTmpDir(const std::string& group,
                               const std::string& name)
{
	const auto d = std::filesystem::temp_directory_path() / group / name;
	std::filesystem::remove_all(d);
	std::filesystem::create_directories(d);
	return d.string();
}

/** NAME inside TMP/GROUP (created, not emptied): a file of a test. */
inline std::string tmpPath(const std::string& group, const std::string& name)
{
	const auto dir = std::filesystem::temp_directory_path() / group;
	std::filesystem::create_directories(dir);
	return (dir / name).string();
}
}  // namespace bims::test
