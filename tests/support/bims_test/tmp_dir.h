// A fresh temporary folder for a test.
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
}  // namespace bims::test
